#include "gpu/renderer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "base/checked.h"
#include "base/errors.h"
#include "gpu/buffer.h"
#include "bvh/bvh.h"
#include "packing/inline_scene.h"
#include "packing/scene_packing.h"
#include "gpu/shader_compiler.h"

namespace vkray::gpu {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One submission aims at about this many ray-primitive tests: a fraction of a second on lavapipe
// with 2 cores, so no single submission runs long (lavapipe has no GPU watchdog to stop one).
constexpr double kTestsPerTile = double(1 << 26);

// Compiling a scene into the shader makes pipeline creation slower and each camera ray with its
// shadow rays cheaper. Measured on lavapipe with the Cornell box (README, "Benchmark"): the compile
// phase 0.36-0.38 s instead of 0.15-0.27 s, about 0.15 s more; the trace at 2048^2 588-604 ms
// instead of 1181-1220 ms, about 0.14 us less per camera ray. They break even near 2^20 camera
// rays, below which the BVH is quicker overall.
constexpr uint64_t kInlineMinCameraRays = uint64_t(1) << 20;

// Pipelines kept for scenes compiled in (`vkray watch` makes one for every edit of a small scene).
constexpr size_t kKeptInlinePipelines = 4;

constexpr vk::DescriptorType kTexel = vk::DescriptorType::eUniformTexelBuffer;

// The descriptor set shaders/trace.comp declares (binding numbers from shared/types.h).
constexpr BindingSlot kTraceBindings[] = {
    {VKRAY_BINDING_FRAME, vk::DescriptorType::eUniformBuffer, "frame"},
    {VKRAY_BINDING_PRIMITIVES, kTexel, "primitives"},
    {VKRAY_BINDING_NORMALS, kTexel, "normals"},
    {VKRAY_BINDING_NODES, kTexel, "nodes"},
    {VKRAY_BINDING_MATERIALS, kTexel, "materials"},
    {VKRAY_BINDING_LIGHTS, kTexel, "lights"},
    {VKRAY_BINDING_OUTPUT, vk::DescriptorType::eStorageBuffer, "output"},
};

// A texel buffer and its view (RGBA32F for vec4 texels, RGBA32UI for uvec4); never empty (Vulkan
// has no zero-sized buffers), the shader is told the real count.
struct TexelBuffer {
  Buffer buffer;
  vk::raii::BufferView view{nullptr};
};

template <typename Texel>
TexelBuffer make_texel_buffer(const Context& ctx, const std::vector<Texel>& texels, const char* what) {
  static_assert(sizeof(Texel) == 16);
  constexpr vk::Format format = std::is_same_v<Texel, glm::uvec4> ? vk::Format::eR32G32B32A32Uint : vk::Format::eR32G32B32A32Sfloat;
  if (texels.size() > ctx.limits().maxTexelBufferElements)
    throw DeviceError(std::string("scene too large for ") + ctx.device_name() + ": " + std::to_string(texels.size()) +
                      " " + what + " texels, maxTexelBufferElements is " +
                      std::to_string(ctx.limits().maxTexelBufferElements));
  static const Texel placeholder(0);
  const Texel* data = texels.empty() ? &placeholder : texels.data();
  TexelBuffer t;
  const vk::DeviceSize bytes = checked_mul(std::max<size_t>(texels.size(), 1), sizeof(Texel), what);
  t.buffer = upload_buffer(ctx, data, bytes, vk::BufferUsageFlagBits::eUniformTexelBuffer);
  t.view = vk::raii::BufferView(ctx.device(), vk::BufferViewCreateInfo({}, *t.buffer.buffer, format, 0, bytes));
  return t;
}

// Refuses, before allocating anything, a scene whose buffers cannot fit the device's memory.
void check_memory(const Context& ctx, const PackedScene& packed) {
  uint64_t texels = packed.nodes.size();
  for (const auto* buffer : {&packed.primitives, &packed.normals, &packed.materials, &packed.lights})
    texels = checked_add(texels, buffer->size(), "scene buffers");
  const uint64_t bytes = checked_mul(texels, sizeof(glm::vec4), "scene buffers");
  const auto memory = ctx.physical_device().getMemoryProperties();
  uint64_t largest_heap = 0;
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & vk::MemoryHeapFlagBits::eDeviceLocal)
      largest_heap = std::max<uint64_t>(largest_heap, memory.memoryHeaps[h].size);
  if (bytes > largest_heap)
    throw DeviceError("scene too large for " + ctx.device_name() + ": its buffers need " + std::to_string(bytes >> 20) +
                      " MiB, the largest device-local memory heap has " + std::to_string(largest_heap >> 20) + " MiB");
}

}  // namespace

TracePipeline::TracePipeline(const Context& ctx, std::filesystem::path shader_dir, const CompiledShader& shader,
                             const vk::raii::PipelineCache* cache)
    : device_(&ctx.device()), cache_(cache), shader_dir_(std::move(shader_dir)), descriptors_(ctx.device(), kTraceBindings) {
  descriptors_.check(shader, shader_dir_ / "trace.comp");
  const vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0, sizeof(TileConstants));
  const vk::DescriptorSetLayout set_layout = *descriptors_.layout();
  layout_ = vk::raii::PipelineLayout(ctx.device(), vk::PipelineLayoutCreateInfo({}, set_layout, push));
  module_ = vk::raii::ShaderModule(ctx.device(), vk::ShaderModuleCreateInfo({}, shader.spirv));
}

TracePipeline::~TracePipeline() = default;

bool use_inline_scene(const GpuScene& scene, const ImageSettings& image, InlineScene policy) {
  if (policy == InlineScene::never || scene.inline_scene().empty()) return false;
  if (policy == InlineScene::always) return true;
  const uint64_t camera_rays = uint64_t(image.width) * image.height * image.samples_per_pixel;
  return camera_rays >= kInlineMinCameraRays;
}

ShaderVariant shader_variant(const GpuScene& scene, const ImageSettings& image, InlineScene policy, bool shadows) {
  ShaderVariant variant;
  variant.spheres = !scene.scene().spheres.empty();
  variant.shadows = shadows;
  if (use_inline_scene(scene, image, policy)) variant.inline_scene = scene.inline_scene();
  return variant;
}

std::shared_ptr<const vk::raii::Pipeline> TracePipeline::pipeline(const ShaderVariant& variant) const {
  const std::lock_guard lock(mutex_);
  if (const auto found = pipelines_.find(variant); found != pipelines_.end()) return found->second;
  auto created = create(variant);
  if (!variant.inline_scene.empty()) {
    inline_order_.push_back(variant);
    if (inline_order_.size() > kKeptInlinePipelines) {  // a render still using it holds its own reference
      pipelines_.erase(inline_order_.front());
      inline_order_.pop_front();
    }
  }
  return pipelines_.emplace(variant, std::move(created)).first->second;
}

std::shared_ptr<const vk::raii::Pipeline> TracePipeline::create(const ShaderVariant& variant) const {
  // A scene compiled in is a module of its own; the module may go once the pipeline exists.
  vk::raii::ShaderModule inline_module{nullptr};
  if (!variant.inline_scene.empty()) {
    const CompiledShader shader =
        compile_compute_shader(shader_dir_ / "trace.comp", {shader_dir_}, {{"inline_scene.glsl", variant.inline_scene}});
    descriptors_.check(shader, shader_dir_ / "trace.comp");
    inline_module = vk::raii::ShaderModule(*device_, vk::ShaderModuleCreateInfo({}, shader.spirv));
  }
  const vk::ShaderModule module = variant.inline_scene.empty() ? *module_ : *inline_module;
  const VkBool32 constants[] = {variant.spheres, variant.shadows};
  const vk::SpecializationMapEntry entries[] = {{VKRAY_SPEC_SPHERES, 0, sizeof(VkBool32)},
                                                {VKRAY_SPEC_SHADOWS, sizeof(VkBool32), sizeof(VkBool32)}};
  const vk::SpecializationInfo specialization(entries, vk::ArrayProxyNoTemporaries<const VkBool32>(constants));
  const vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, module, "main", &specialization);
  return std::make_shared<const vk::raii::Pipeline>(
      *device_, cache_ ? vk::Optional<const vk::raii::PipelineCache>(*cache_) : nullptr,
      vk::ComputePipelineCreateInfo({}, stage, *layout_));
}

uint32_t tile_side(const Scene& scene, const ImageSettings& image) {
  // With the BVH a ray visits on the order of log2(N) nodes and a few leaves.
  const double primitives = double(scene.triangles.size() + scene.spheres.size()) + 1.0;
  const double tests_per_sample = (8.0 + 4.0 * std::log2(primitives)) * (1.0 + double(scene.lights.size()));
  const double pixels = kTestsPerTile / (tests_per_sample * image.samples_per_pixel);
  const uint32_t side = static_cast<uint32_t>(std::sqrt(pixels)) / VKRAY_WORKGROUP_X * VKRAY_WORKGROUP_X;
  const uint32_t largest = (std::max(image.width, image.height) + VKRAY_WORKGROUP_X - 1) / VKRAY_WORKGROUP_X * VKRAY_WORKGROUP_X;
  return std::clamp<uint32_t>(side, VKRAY_WORKGROUP_X, largest);
}

struct GpuScene::Buffers {
  TexelBuffer primitives, normals, nodes, materials, lights;
};

GpuScene::GpuScene(const Context& ctx, const Scene& scene, const Bvh* prebuilt) : scene_(&scene) {
  const auto start = Clock::now();
  Bvh built;
  if (!prebuilt) built = build_bvh(primitive_boxes(scene));
  const Bvh& bvh = prebuilt ? *prebuilt : built;
  bvh_seconds_ = bvh.build_seconds;
  primitive_count_ = uint32_t(bvh.order.size());
  const PackedScene packed = pack_scene(scene, bvh);
  if (primitive_count_ <= kMaxInlinePrimitives) inline_scene_ = inline_scene_glsl(packed);
  check_memory(ctx, packed);
  buffers_ = std::make_unique<Buffers>(Buffers{make_texel_buffer(ctx, packed.primitives, "primitive"),
                                               make_texel_buffer(ctx, packed.normals, "normal"),
                                               make_texel_buffer(ctx, packed.nodes, "BVH node"),
                                               make_texel_buffer(ctx, packed.materials, "material"),
                                               make_texel_buffer(ctx, packed.lights, "light")});
  upload_seconds_ = seconds_since(start);
}

GpuScene::~GpuScene() = default;
GpuScene::GpuScene(GpuScene&&) noexcept = default;

Image render(Context& ctx, const TracePipeline& pipeline, const Scene& scene, const ImageSettings& image,
             const RenderOptions& options, RenderStats* stats_out) {
  const GpuScene gpu_scene(ctx, scene);
  Image result = render(ctx, pipeline, gpu_scene, image, options, stats_out);
  if (stats_out) {
    stats_out->bvh_seconds = gpu_scene.bvh_seconds();
    stats_out->upload_seconds += gpu_scene.upload_seconds();
  }
  return result;
}

Image render(Context& ctx, const TracePipeline& pipeline, const GpuScene& gpu_scene, const ImageSettings& image,
             const RenderOptions& options, RenderStats* stats_out) {
  RenderStats stats;
  const vk::raii::Device& device = ctx.device();
  const Scene& scene = gpu_scene.scene();

  // ---- per-frame data: uniforms, output ----
  auto start = Clock::now();
  FrameUniforms frame = pack_frame(scene, gpu_scene.primitive_count(), image);
  const vk::DeviceSize pixel_bytes =
      checked_mul(checked_mul(image.width, image.height, "output image"), sizeof(glm::vec4), "output image");
  if (pixel_bytes > ctx.limits().maxStorageBufferRange)
    throw DeviceError("image too large for " + ctx.device_name() + ": " + std::to_string(pixel_bytes) +
                      " bytes of output, maxStorageBufferRange is " + std::to_string(ctx.limits().maxStorageBufferRange));
  Buffer frame_buffer = upload_buffer(ctx, &frame, sizeof(frame), vk::BufferUsageFlagBits::eUniformBuffer);
  using M = vk::MemoryPropertyFlagBits;
  const Buffer output = create_buffer(ctx, pixel_bytes, vk::BufferUsageFlagBits::eStorageBuffer, M::eHostVisible,
                                      M::eHostCached);

  const GpuScene::Buffers& b = *gpu_scene.buffers_;
  const DescriptorSet descriptor_set = pipeline.descriptors()
                                           .writer()
                                           .buffer(VKRAY_BINDING_FRAME, *frame_buffer.buffer)
                                           .texel_buffer(VKRAY_BINDING_PRIMITIVES, *b.primitives.view)
                                           .texel_buffer(VKRAY_BINDING_NORMALS, *b.normals.view)
                                           .texel_buffer(VKRAY_BINDING_NODES, *b.nodes.view)
                                           .texel_buffer(VKRAY_BINDING_MATERIALS, *b.materials.view)
                                           .texel_buffer(VKRAY_BINDING_LIGHTS, *b.lights.view)
                                           .buffer(VKRAY_BINDING_OUTPUT, *output.buffer)
                                           .write();
  const vk::DescriptorSet set = descriptor_set.get();
  stats.upload_seconds = seconds_since(start);

  // ---- trace, one submission per tile ----
  const ShaderVariant variant = shader_variant(gpu_scene, image, options.inline_scene, options.shadows);
  stats.inline_scene = !variant.inline_scene.empty();
  const auto compute_pipeline = pipeline.pipeline(variant);  // compiled here unless asked for before
  start = Clock::now();
  const vk::raii::CommandPool command_pool(device, {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx.queue_family()});
  vk::raii::CommandBuffers cbs(device, {*command_pool, vk::CommandBufferLevel::ePrimary, 1});
  const vk::raii::CommandBuffer& cb = cbs[0];
  const vk::raii::Fence fence(device, vk::FenceCreateInfo{});
  const uint32_t side = options.tile_side ? options.tile_side : tile_side(scene, image);
  const uint32_t tiles_x = (image.width + side - 1) / side, tiles_y = (image.height + side - 1) / side;
  const uint32_t tile_count = tiles_x * tiles_y;
  for (uint32_t tile_index = 0; tile_index < tile_count; ++tile_index) {
    TileConstants tile;
    tile.x0 = (tile_index % tiles_x) * side;
    tile.y0 = (tile_index / tiles_x) * side;
    tile.width = std::min(side, image.width - tile.x0);
    tile.height = std::min(side, image.height - tile.y0);
    const uint32_t groups_x = (tile.width + VKRAY_WORKGROUP_X - 1) / VKRAY_WORKGROUP_X;
    const uint32_t groups_y = (tile.height + VKRAY_WORKGROUP_Y - 1) / VKRAY_WORKGROUP_Y;
    tile.row_stride = row_stride(groups_y);

    cb.reset();
    cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
    cb.bindPipeline(vk::PipelineBindPoint::eCompute, **compute_pipeline);
    cb.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *pipeline.layout(), 0, set, {});
    cb.pushConstants<TileConstants>(*pipeline.layout(), vk::ShaderStageFlagBits::eCompute, 0, tile);
    cb.dispatch(groups_x, groups_y, 1);
    // The shader's writes are read by the host after the fence.
    const vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
    cb.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
    cb.end();
    const vk::CommandBuffer raw = *cb;
    ctx.queue().submit(vk::SubmitInfo({}, {}, raw), *fence);
    try {
      ctx.wait(fence, options.tile_timeout, "a render tile");
    } catch (const DeviceError& e) {
      throw TimeoutError(e.what());
    }
    device.resetFences(*fence);
    if (options.progress) options.progress(tile_index + 1, tile_count);
    if (options.cancel && tile_index + 1 < tile_count && options.cancel()) throw Cancelled();
  }
  stats.trace_seconds = seconds_since(start);
  stats.tiles = tile_count;

  // ---- read back ----
  start = Clock::now();
  output.invalidate(device);
  Image result(image.width, image.height);
  const auto* texels = static_cast<const glm::vec4*>(output.mapped);
  for (size_t i = 0; i < result.pixels.size(); ++i) {
    result.pixels[i] = glm::vec3(texels[i]);
    stats.rays += std::bit_cast<uint32_t>(texels[i].w);
  }
  stats.readback_seconds = seconds_since(start);
  ctx.check_validation("render");
  if (stats_out) *stats_out = stats;
  return result;
}

}  // namespace vkray::gpu
