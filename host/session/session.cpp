#include "session/session.h"

#include <chrono>

#include "base/errors.h"
#include "bvh/bvh.h"
#include "gpu/context.h"
#include "gpu/device_scene.h"
#include "gpu/pipeline.h"
#include "gpu/renderer.h"
#include "gpu/shader_compiler.h"
#include "session/paths.h"

namespace vkray {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Runs `work` on the device, turning Vulkan-Hpp's report of a lost device into vkray's.
template <typename Work>
auto on_device(Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const vk::DeviceLostError& e) {
    throw DeviceLostError(std::string(e.what()) + ": the device was lost");
  }
}

// Compiling a scene into the shader makes pipeline creation slower and each camera ray with its
// shadow rays cheaper; on lavapipe the two break even near 2^20 camera rays (docs/design.md,
// "Small scenes compiled into the shader").
constexpr uint64_t kInlineMinCameraRays = uint64_t(1) << 20;

}  // namespace

struct Session::Shaders {
  // Pipelines built from SPIR-V seen before in this session come from here instead of the driver's
  // compiler (Mesa also keeps its own on-disk cache across processes).
  std::shared_ptr<const vk::raii::PipelineCache> cache;
  std::shared_ptr<const gpu::TracePipeline> pipeline;
};

Session::Session(const SessionOptions& options)
    : options_(options), shader_dir_(options.shader_dir.empty() ? default_shader_dir() : options.shader_dir) {
  gpu::ContextOptions context_options;
  context_options.device = options.device;
  if (options.validation) validation_log_ = std::make_shared<gpu::ValidationLog>();
  context_options.validation_log = validation_log_;
  ctx_ = std::make_shared<const gpu::Context>(context_options);
  shaders_ = std::make_unique<Shaders>();
  shaders_->cache = std::make_shared<const vk::raii::PipelineCache>(ctx_->device(), vk::PipelineCacheCreateInfo{});
  renderer_ = std::make_unique<gpu::Renderer>(ctx_);
}

Session::~Session() = default;

const std::string& Session::device_name() const { return ctx_->device_name(); }
const std::string& Session::driver_name() const { return ctx_->driver_name(); }
std::string Session::device_description() const { return device_name() + " (" + driver_name() + ")"; }

bool Session::has_shaders() const { return shaders_->pipeline != nullptr; }

std::vector<std::filesystem::path> Session::shader_sources() const {
  if (!has_shaders()) return {shader_dir_ / "trace.comp"};
  return shaders_->pipeline->shader().sources;
}

Session::ShaderCompile Session::compile_shaders() {
  const auto start = Clock::now();
  gpu::CompiledShader compiled = gpu::compile_compute_shader(shader_dir_ / "trace.comp", {shader_dir_});
  // The same SPIR-V keeps every pipeline, unless one has a scene compiled in: its code comes from
  // the shader files as they are now, which this SPIR-V (without a scene) says nothing about.
  const bool kept = has_shaders() && compiled.spirv == shaders_->pipeline->shader().spirv &&
                    !shaders_->pipeline->has_inline_variants();
  if (!kept) {
    shaders_->pipeline = on_device([&] {
      return std::make_shared<const gpu::TracePipeline>(ctx_, shader_dir_, std::move(compiled), shaders_->cache);
    });
    check_validation("shader module creation");
  }
  return {seconds_since(start), kept};
}

const Scene& DeviceScene::scene() const { return scene_->scene(); }
double DeviceScene::bvh_seconds() const { return scene_->bvh_seconds(); }
double DeviceScene::upload_seconds() const { return scene_->upload_seconds(); }

DeviceScene Session::upload(std::shared_ptr<const Scene> scene, const Bvh* bvh) {
  DeviceScene uploaded(on_device([&] { return std::make_shared<const gpu::GpuScene>(ctx_, std::move(scene), bvh); }));
  check_validation("scene upload");
  return uploaded;
}

namespace {

bool use_inline_scene(const gpu::GpuScene& scene, const ImageSettings& image, InlineScene policy) {
  if (policy == InlineScene::never || scene.inline_scene().empty()) return false;
  if (policy == InlineScene::always) return true;
  const uint64_t camera_rays = uint64_t(image.width) * image.height * image.samples_per_pixel;
  return camera_rays >= kInlineMinCameraRays;
}

gpu::ShaderVariant shader_variant(const gpu::GpuScene& scene, const RenderOptions& options) {
  gpu::ShaderVariant variant;
  variant.spheres = !scene.scene().spheres.empty();
  variant.shadows = options.shadows;
  if (use_inline_scene(scene, image_settings(scene.scene(), options), options.inline_scene))
    variant.inline_scene = scene.inline_scene();
  return variant;
}

}  // namespace

bool Session::compiles_scene_in(const DeviceScene& scene, const RenderOptions& options) const {
  return use_inline_scene(*scene.scene_, image_settings(scene.scene(), options), options.inline_scene);
}

double Session::prepare(const DeviceScene& scene, const RenderOptions& options) {
  const auto start = Clock::now();
  if (!has_shaders()) compile_shaders();
  on_device([&] { return shaders_->pipeline->pipeline(shader_variant(*scene.scene_, options)); });
  check_validation("pipeline creation");
  return seconds_since(start);
}

RenderResult Session::render(const DeviceScene& scene, const RenderOptions& options) {
  gpu::TraceRequest request;
  request.image = image_settings(scene.scene(), options);
  request.variant = shader_variant(*scene.scene_, options);
  request.tile_timeout = options.tile_timeout;
  request.tile_side = options.tile_side;
  if (options.progress)
    request.progress = [&options](uint32_t done, uint32_t total) { options.progress("tiles", done, total); };
  request.cancel = options.cancel;
  RenderResult result;
  result.stats.inline_scene = !request.variant.inline_scene.empty();
  result.stats.compile_seconds = prepare(scene, options);  // nothing when prepared before
  gpu::TraceStats trace;
  result.image = on_device([&] { return renderer_->render(shaders_->pipeline, scene.scene_, request, &trace); });
  check_validation("render");
  result.stats.upload_seconds = trace.upload_seconds;
  result.stats.trace_seconds = trace.trace_seconds;
  result.stats.readback_seconds = trace.readback_seconds;
  result.stats.rays = trace.rays;
  result.stats.tiles = trace.tiles;
  return result;
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
  // validation layer's report of what was left alive arrives before the check below.
  renderer_.reset();
  shaders_.reset();
  const bool last = ctx_.use_count() == 1;
  ctx_.reset();
  if (!last && !gpu::work_left_running())
    throw InternalError("Session::close() while a DeviceScene is still held: the device outlives the session");
  check_validation("device teardown");
}

bool device_work_left_running() { return gpu::work_left_running(); }

}  // namespace vkray
