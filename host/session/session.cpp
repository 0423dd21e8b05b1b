#include "session/session.h"

#include <algorithm>
#include <chrono>
#include <future>
#include <optional>
#include <string>
#include <system_error>

#include "base/errors.h"
#include "base/hash.h"
#include "base/timing.h"
#include "bvh/bvh.h"
#include "gpu/accumulator.h"
#include "gpu/context.h"
#include "gpu/scene_buffers.h"
#include "gpu/pipeline.h"
#include "gpu/renderer.h"
#include "gpu/shader_cache.h"
#include "gpu/shader_compiler.h"
#include "session/paths.h"
#include "session/on_device.h"

namespace vkray {
namespace {

// Compiling a scene into the shader makes pipeline creation slower (on lavapipe with 2 cores and the
// shader caches warm, by 15-25 ms a primitive) and each ray cheaper, by more the more a sample traces
// (docs/design.md, "Small scenes compiled into the shader"). Measured break-even in camera rays: the
// Cornell box (30 triangles) near 2^24 under `direct`, `cornell-path` (32) near 2^20, the sphere grid
// (44) near 2^23 and the grid with 92 primitives near 2^26 under `path`. So `auto` compiles a scene
// in from kInlineCameraRaysPerPrimitive camera rays a primitive under `path`, growing with the square
// of the primitives past kInlineSteeperFrom (each ray saves less there, the compile grows on), 4x
// that under `direct`, and under `direct` only up to 32 primitives: with more, its rays are no
// cheaper compiled in (60 triangles: the same trace time).
constexpr uint64_t kInlineCameraRaysPerPrimitive = uint64_t(1) << 17;
constexpr double kInlineSteeperFrom = 44.0;
constexpr uint32_t kInlineMaxDirectPrimitives = 32;

// A tile that an interrupt left running ends with its submission (about kSubmissionSeconds, at most
// the render's tile timeout, which defaults to this): an upload or close() waits this long for it.
constexpr std::chrono::milliseconds kInterruptedTileWait{60000};

}  // namespace

struct Session::Shaders {
  // Pipelines built from SPIR-V seen before in this session come from here instead of the driver's
  // compiler (Mesa also keeps its own on-disk cache across processes).
  std::shared_ptr<const vk::raii::PipelineCache> cache;
  std::shared_ptr<const gpu::TracePipeline> pipeline;
  std::vector<std::filesystem::path> sources;  // of the last compile that succeeded
};

Session::Session(const SessionOptions& options)
    : shader_dir_(options.shader_dir.empty() ? default_shader_dir() : options.shader_dir),
      shader_cache_(gpu::shader_cache_dir()) {
  gpu::ContextOptions context_options;
  context_options.device = options.device;
  if (options.validation) validation_log_ = std::make_shared<gpu::ValidationLog>();
  context_options.validation_log = validation_log_;
  context_options.surface = options.surface;
  ctx_ = std::make_shared<const gpu::Context>(context_options);
  shaders_ = std::make_unique<Shaders>();
  shaders_->cache = std::make_shared<const vk::raii::PipelineCache>(ctx_->device(), vk::PipelineCacheCreateInfo{});
  renderer_ = std::make_unique<gpu::Renderer>(ctx_);
}

Session::~Session() = default;

const gpu::Context& Session::device() const {
  if (!ctx_) throw UsageError("the session is closed: its device is gone");
  return *ctx_;
}

const std::string& Session::device_name() const { return device().device_name(); }
const std::string& Session::driver_name() const { return device().driver_name(); }
const gpu::DeviceInfo& Session::device_info() const { return device().info(); }
std::string Session::device_description() const { return device_name() + " (" + driver_name() + ")"; }

bool Session::has_shaders() const { return ctx_ && shaders_->pipeline != nullptr; }

std::vector<std::filesystem::path> Session::shader_sources() const {
  if (!has_shaders()) return {shader_dir_ / "trace.comp"};
  return shaders_->sources;
}

Session::ShaderCompile Session::compile_shaders() {
  device();
  const auto start = Clock::now();
  // The pipeline in use with a scene compiled in is compiled and specialized again beside trace.comp
  // (each holds one core), where the next render's pipeline finds it. Its errors are that render's
  // to report.
  std::future<void> ahead;
  if (has_shaders() && shader_cache_)
    if (std::optional<gpu::ShaderVariant> variant = shaders_->pipeline->newest_inline_variant()) try {
        ahead = std::async(std::launch::async, [cache = shader_cache_, dir = shader_dir_, variant = std::move(*variant)] {
          try {
            gpu::prepare_inline_variant(cache, dir, variant);
          } catch (...) {  // the render that needs the variant compiles it again, and reports
          }
        });
      } catch (const std::system_error&) {  // no thread to be had: the render compiles it, as without
      }
  gpu::CompiledShader compiled = gpu::compile_compute_shader_cached(shader_cache_, shader_dir_ / "trace.comp", {shader_dir_});
  if (ahead.valid()) ahead.wait();
  std::vector<std::filesystem::path> sources = compiled.sources;
  const bool changed = !has_shaders() || compiled.spirv != shaders_->pipeline->shader().spirv;
  if (changed) {
    shaders_->pipeline = on_device([&] {
      return std::make_shared<const gpu::TracePipeline>(ctx_, shader_dir_, std::move(compiled), shaders_->cache, shader_cache_);
    });
    check_validation("shader module creation");
  } else {
    // The same SPIR-V keeps its pipelines, but not those with a scene compiled in: their code
    // comes from the shader files as they are now, which this SPIR-V (without a scene) does not show.
    shaders_->pipeline->forget_inline_variants();
  }
  shaders_->sources = std::move(sources);
  return {seconds_since(start), changed};
}

const Scene& DeviceScene::scene() const { return buffers_->scene(); }
double DeviceScene::upload_seconds() const { return buffers_->upload_seconds(); }
double DeviceScene::bvh_seconds() const { return buffers_->bvh_seconds(); }
double DeviceScene::environment_seconds() const { return buffers_->environment_seconds(); }
bool DeviceScene::shares_geometry() const { return buffers_->shares_geometry(); }

BackgroundBvh::BackgroundBvh(std::shared_ptr<const Scene> scene) : stop_(std::make_shared<std::atomic<bool>>(false)) {
  build_ = std::async(std::launch::async,
                      [scene = std::move(scene), stop = stop_] { return build_scene_bvh(*scene, 0, stop.get()); });
}

BackgroundBvh::~BackgroundBvh() {
  stop_->store(true, std::memory_order_relaxed);
  if (build_.valid()) build_.wait();  // milliseconds: the build checks the flag at every node
}

SceneBvh BackgroundBvh::get() { return build_.get(); }

DeviceScene Session::upload(std::shared_ptr<const Scene> scene, std::shared_ptr<const SceneBvh> bvh) {
  device();
  // A tree built for another scene would send the packing past the primitives' ends.
  if (bvh && (bvh->primitives.order.size() != scene->triangles.size() + scene->spheres.size() ||
              bvh->meshes.size() != scene->meshes.size() || bvh->instances.order.size() != scene->instances.size()))
    throw UsageError("a BVH over " + std::to_string(bvh->primitives.order.size()) + " primitives and " +
                     std::to_string(bvh->instances.order.size()) + " instances for a scene of " +
                     std::to_string(scene->triangles.size() + scene->spheres.size()) + " and " + std::to_string(scene->instances.size()));
  // An upload may go through the queue, behind a tile that timed out and still runs: refuse at
  // once rather than wait behind it.
  if (renderer_->busy_after_interrupts(kInterruptedTileWait))
    throw TimeoutError("the device is still running a render tile that timed out; the scene was not uploaded");
  if (!bvh) bvh = std::make_shared<const SceneBvh>(build_scene_bvh(*scene));
  DeviceScene uploaded(on_device([&] { return std::make_shared<const gpu::SceneBuffers>(ctx_, std::move(scene), bvh.get()); }),
                       bvh);
  check_validation("scene upload");
  return uploaded;
}

DeviceScene Session::upload_changes(const DeviceScene& previous, std::shared_ptr<const Scene> scene) {
  const gpu::SceneBuffers& same = own(previous);
  if (!same_geometry(same.scene(), *scene)) return upload(std::move(scene));
  if (renderer_->busy_after_interrupts(kInterruptedTileWait))
    throw TimeoutError("the device is still running a render tile that timed out; the scene was not uploaded");
  DeviceScene uploaded(on_device([&] { return std::make_shared<const gpu::SceneBuffers>(same, std::move(scene)); }),
                       previous.bvh_);
  check_validation("scene upload");
  return uploaded;
}

namespace {

// By the whole image's camera rays, never a region's: the parts of a render must trace the same code
// as the whole render, or they would not assemble into it bit for bit.
bool use_inline_scene(const gpu::SceneBuffers& scene, const ImageSettings& image, InlineScene policy) {
  if (policy == InlineScene::never || scene.inline_scene().empty()) return false;
  if (policy == InlineScene::always) return true;
  const bool direct = scene.scene().integrator.type == Integrator::Type::direct;
  if (direct && scene.primitive_count() > kInlineMaxDirectPrimitives) return false;
  const uint64_t camera_rays = uint64_t(image.width) * image.height * image.samples_per_pixel;
  const double primitives = scene.primitive_count();
  const double steeper = std::max(1.0, (primitives / kInlineSteeperFrom) * (primitives / kInlineSteeperFrom));
  return double(camera_rays) >= double(kInlineCameraRaysPerPrimitive) * (direct ? 4.0 : 1.0) * primitives * steeper;
}

gpu::ShaderVariant shader_variant(const gpu::SceneBuffers& scene, const RenderOptions& options) {
  gpu::ShaderVariant variant;
  variant.spheres = !scene.scene().spheres.empty();
  variant.shadows = options.shadows;
  const Scene& s = scene.scene();
  variant.path = s.integrator.type == Integrator::Type::path;
  variant.emitters = scene.lighting().emitter_count > 0;
  variant.non_diffuse = std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.properties() != VKRAY_BSDF_DIFFUSE; });
  variant.materials = 0;
  for (const Material& m : s.materials) variant.materials |= 1u << uint32_t(m.type);
  variant.aovs = options.aovs;
  variant.textures = std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.textured(); });
  variant.single_sided = std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return !m.double_sided; });
  variant.normal_maps = std::any_of(s.materials.begin(), s.materials.end(), [](const Material& m) { return m.normal_texture.present(); });
  variant.alpha = scene.see_through();
  variant.shading_normals = scene.vertex_normals() || variant.normal_maps;
  variant.point_lights = !s.lights.empty();
  variant.background = variant.path && s.background != glm::vec3(0.0f);  // only paths sample it
  variant.vertex_colours = scene.vertex_colours();
  variant.instances = scene.instances();
  variant.environment = scene.lighting().environment_width > 0;
  variant.environment_sampled = options.sample_environment;
  if (use_inline_scene(scene, image_settings(scene.scene(), options), options.inline_scene))
    variant.inline_scene = scene.inline_scene();
  return variant;
}

}  // namespace

const gpu::SceneBuffers& Session::own(const DeviceScene& scene) const {
  if (&scene.buffers_->context() != &device()) throw UsageError("a scene uploaded by another session");
  return *scene.buffers_;
}

bool Session::compiles_scene_in(const DeviceScene& scene, const RenderOptions& options) const {
  return use_inline_scene(own(scene), image_settings(scene.scene(), options), options.inline_scene);
}

double Session::prepare(const DeviceScene& scene, const RenderOptions& options) {
  const gpu::SceneBuffers& buffers = own(scene);
  const auto start = Clock::now();
  if (!has_shaders()) compile_shaders();
  on_device([&] { return shaders_->pipeline->pipeline(shader_variant(buffers, options)); });
  check_validation("pipeline creation");
  return seconds_since(start);
}

RenderResult Session::render(const DeviceScene& scene, const RenderOptions& options) {
  gpu::TraceRequest request;
  request.image = image_settings(scene.scene(), options);
  request.region = options.region ? resolve_region(scene.scene(), request.image, *options.region, scene.bvh_.get())
                                  : full_region(request.image.width, request.image.height);
  request.variant = shader_variant(own(scene), options);
  request.tile_timeout = options.tile_timeout;
  request.tile_side = options.tile_side;
  if (options.progress)
    request.progress = [&options](uint32_t done, uint32_t total) { options.progress("pixels", done, total); };
  prepare(scene, options);  // nothing to do when prepared before
  gpu::TraceStats trace;
  RenderResult result;
  if (options.aovs) result.aovs.emplace();
  result.image = on_device([&] {
    return renderer_->render(shaders_->pipeline, scene.buffers_, request, &trace, result.aovs ? &*result.aovs : nullptr);
  });
  check_validation("render");
  result.settings = request.image;
  result.region = request.region;
  result.part = options.region.has_value();
  const std::vector<uint32_t>& spirv = shaders_->pipeline->shader().spirv;
  result.shader = hash_hex(spirv.data(), spirv.size() * sizeof(uint32_t));
  result.stats.upload_seconds = trace.upload_seconds;
  result.stats.trace_seconds = trace.trace_seconds;
  result.stats.readback_seconds = trace.readback_seconds;
  result.stats.rays = trace.rays;
  result.stats.tiles = trace.tiles;
  result.stats.inline_scene = !request.variant.inline_scene.empty();
  return result;
}

std::unique_ptr<ProgressiveRender> Session::start_progressive(const DeviceScene& scene, const RenderOptions& options,
                                                              double rate_hint) {
  if (options.region) throw UsageError("a progressive render of a region");
  const ImageSettings image = image_settings(scene.scene(), options);
  prepare(scene, options);
  auto accumulator = on_device([&] {
    return std::make_unique<gpu::Accumulator>(ctx_, shaders_->pipeline, scene.buffers_, image, shader_variant(own(scene), options));
  });
  check_validation("progressive render setup");
  return std::unique_ptr<ProgressiveRender>(new ProgressiveRender(std::move(accumulator), image, options.tile_timeout, rate_hint));
}

void Session::check_validation(const char* during) {
  if (!validation_log_) return;
  const auto messages = validation_log_->messages();
  if (messages.size() == validation_seen_) return;
  std::string text = std::to_string(messages.size() - validation_seen_) + " validation message(s) during " + during +
                     "; the first:\n  " + messages[validation_seen_];
  validation_seen_ = messages.size();
  throw DeviceError(text);
}

void Session::close() {
  if (!ctx_) return;
  // Everything that keeps the device alive goes first, so that the device is destroyed here and the
  // validation layer's report of what was left alive arrives before the check below. Work a
  // timed-out tile left running keeps its part alive (gpu/renderer.h): the device stays then.
  const bool work_left = renderer_->busy_after_interrupts(kInterruptedTileWait);
  renderer_.reset();
  shaders_.reset();
  const bool last = ctx_.use_count() == 1;
  ctx_.reset();
  if (!last && !work_left)
    throw InternalError("Session::close() while a DeviceScene is still held: the device outlives the session");
  check_validation("device teardown");
}

bool device_work_left_running() { return gpu::work_left_running(); }

}  // namespace vkray
