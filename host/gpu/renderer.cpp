#include "gpu/renderer.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "base/checked.h"
#include "base/errors.h"
#include "base/interrupt.h"
#include "base/timing.h"
#include "gpu/buffer.h"
#include "packing/scene_packing.h"
#include "shared/types.h"

namespace vkray::gpu {
namespace {

// One submission aims at about this many ray-primitive tests: a fraction of a second on lavapipe
// with 2 cores, so no single submission runs long.
constexpr double kTestsPerTile = double(1 << 26);

// Ray-primitive tests one sample costs, roughly: a ray visits on the order of log2(N) nodes and a few
// leaves, for the camera ray and each light's shadow ray.
double tests_per_sample(const Scene& scene) {
  const double primitives = double(scene.triangles.size() + scene.spheres.size()) + 1.0;
  return (8.0 + 4.0 * std::log2(primitives)) * (1.0 + double(scene.lights.size()));
}

// The most samples of a pixel one dispatch traces. llvmpipe ends every loop of an invocation once
// the invocation has made 65535 loop iterations in all (Mesa 22.3's loop limiter), without a word:
// at 16 x 16 pixels of the Cornell box, 2048 spp in one dispatch gave an image 29% too dark (1024 did
// not). A sample's loop iterations (the sample loop, the light loop, each ray's BVH walk) are bounded
// by its estimated tests; a dispatch gets at most half the limit of them, and at most 64 samples.
uint32_t samples_in_one_dispatch(const Scene& scene) {
  return uint32_t(std::clamp(32768.0 / tests_per_sample(scene), 1.0, 64.0));
}

}  // namespace

// Everything one render's submissions use. Declaration order is destruction order reversed: the
// command buffer before its pool, the descriptor set before the buffers, the pipeline and the
// scene (and through them the device) last.
struct Renderer::Frame {
  std::shared_ptr<const TracePipeline> trace_pipeline;
  std::shared_ptr<const GpuScene> scene;
  std::shared_ptr<const vk::raii::Pipeline> pipeline;
  Buffer uniforms;
  Buffer output;  // two tiles' slots: one traced while the other is read back
  std::optional<DescriptorSet> descriptors;
  vk::raii::CommandPool command_pool{nullptr};
  vk::raii::CommandBuffers command_buffers{nullptr};  // one per slot
  std::vector<vk::raii::Fence> fences;                // one per slot
  std::vector<vk::Fence> in_flight;                   // submitted and not yet waited for
};

Renderer::Renderer(std::shared_ptr<const Context> ctx) : ctx_(std::move(ctx)) {}

Renderer::~Renderer() {
  try {
    if (!busy(std::chrono::milliseconds(0))) return;
  } catch (...) {  // a failed wait says nothing of whether the work is done: leave it, as below
  }
  // The device is still running a tile that timed out. Destroying what it uses (or the device)
  // could hang or crash the driver: leave all of it, and the Context it keeps alive, to the process.
  for (auto& frame : abandoned_) static_cast<void>(frame.release());
  ctx_->abandon_work();
}

bool Renderer::busy(std::chrono::milliseconds wait) {
  const auto deadline = Clock::now() + wait;
  for (auto it = abandoned_.begin(); it != abandoned_.end();) {
    const auto left = std::max(std::chrono::nanoseconds(0), std::chrono::nanoseconds(deadline - Clock::now()));
    try {
      const auto& fences = (*it)->in_flight;
      if (!fences.empty() &&
          ctx_->device().waitForFences(fences, VK_TRUE, uint64_t(left.count())) == vk::Result::eTimeout)
        return true;
    } catch (const vk::DeviceLostError&) {  // nothing runs on a lost device any more
    }
    it = abandoned_.erase(it);
  }
  return false;
}

Image Renderer::render(std::shared_ptr<const TracePipeline> trace_pipeline, std::shared_ptr<const GpuScene> scene,
                       const TraceRequest& request, TraceStats* stats_out) {
  if (busy(request.tile_timeout))
    throw TimeoutError("the device is still running a render tile that timed out before, " +
                       std::to_string(request.tile_timeout.count()) + " ms later");
  TraceStats stats;
  const vk::raii::Device& device = ctx_->device();
  const ImageSettings& image = request.image;

  // ---- per-frame data: uniforms, output, descriptors ----
  auto start = Clock::now();
  // The output holds two tiles, not the image: any image size fits the device's
  // maxStorageBufferRange (128 MiB on lavapipe), the tile made smaller when two would not.
  constexpr uint32_t kSlots = 2;
  uint32_t side = request.tile_side ? request.tile_side : tile_side(scene->scene(), image);
  const auto slot_pixels = [&] { return uint64_t(std::min(side, image.width)) * std::min(side, image.height); };
  while (side > VKRAY_WORKGROUP_X && kSlots * slot_pixels() * sizeof(glm::vec4) > ctx_->limits().maxStorageBufferRange)
    side -= VKRAY_WORKGROUP_X;
  const vk::DeviceSize output_bytes = kSlots * slot_pixels() * sizeof(glm::vec4);
  if (output_bytes > ctx_->limits().maxStorageBufferRange)
    throw DeviceError("a render tile does not fit " + ctx_->device_name() + ": " + std::to_string(output_bytes) +
                      " bytes of output, maxStorageBufferRange is " + std::to_string(ctx_->limits().maxStorageBufferRange));
  Image result(image.width, image.height);  // the host's copy, filled tile by tile
  auto frame = std::make_unique<Frame>();
  frame->trace_pipeline = std::move(trace_pipeline);
  frame->scene = std::move(scene);
  const FrameUniforms uniforms = pack_frame(frame->scene->scene(), frame->scene->primitive_count(), image);
  frame->uniforms = upload_buffer(*ctx_, &uniforms, sizeof(uniforms), vk::BufferUsageFlagBits::eUniformBuffer);
  using M = vk::MemoryPropertyFlagBits;
  frame->output = create_buffer(*ctx_, output_bytes, vk::BufferUsageFlagBits::eStorageBuffer, M::eHostVisible, M::eHostCached);
  DescriptorWriter writer = frame->trace_pipeline->descriptors().writer();
  writer.buffer(VKRAY_BINDING_FRAME, *frame->uniforms.buffer).buffer(VKRAY_BINDING_OUTPUT, *frame->output.buffer);
  frame->scene->bind(writer);
  frame->descriptors = writer.write();
  stats.upload_seconds = seconds_since(start);

  // ---- trace, one submission per tile; each tile read back while the next one traces ----
  frame->pipeline = frame->trace_pipeline->pipeline(request.variant);  // compiled here unless asked for before
  start = Clock::now();
  double readback_seconds = 0;
  frame->command_pool = vk::raii::CommandPool(device, {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx_->queue_family()});
  frame->command_buffers = vk::raii::CommandBuffers(device, {*frame->command_pool, vk::CommandBufferLevel::ePrimary, kSlots});
  frame->fences.reserve(kSlots);
  for (uint32_t slot = 0; slot < kSlots; ++slot) frame->fences.emplace_back(device, vk::FenceCreateInfo{});
  frame->in_flight.reserve(kSlots);  // so that recording a submission cannot fail after it is made
  abandoned_.reserve(abandoned_.size() + 1);  // nor keeping the frame when the device still runs it
  const vk::PipelineLayout layout = *frame->trace_pipeline->layout();
  const uint32_t tiles_x = (image.width + side - 1) / side, tiles_y = (image.height + side - 1) / side;
  const uint32_t tile_count = tiles_x * tiles_y;
  const uint32_t samples_per_dispatch = samples_in_one_dispatch(frame->scene->scene());
  const auto tile_at = [&](uint32_t tile_index) {
    TileConstants tile{};
    tile.x0 = (tile_index % tiles_x) * side;
    tile.y0 = (tile_index / tiles_x) * side;
    tile.width = std::min(side, image.width - tile.x0);
    tile.height = std::min(side, image.height - tile.y0);
    tile.row_stride = row_stride((tile.height + VKRAY_WORKGROUP_Y - 1) / VKRAY_WORKGROUP_Y);
    tile.output_offset = uint32_t((tile_index % kSlots) * slot_pixels());
    return tile;
  };
  const auto submit = [&](uint32_t tile_index) {
    TileConstants tile = tile_at(tile_index);
    const uint32_t groups_x = (tile.width + VKRAY_WORKGROUP_X - 1) / VKRAY_WORKGROUP_X;
    const uint32_t groups_y = (tile.height + VKRAY_WORKGROUP_Y - 1) / VKRAY_WORKGROUP_Y;
    const vk::raii::CommandBuffer& cb = frame->command_buffers[tile_index % kSlots];
    // The slot's command buffer and output were last used by tile_index - 2, waited for and read.
    cb.reset();
    cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
    cb.bindPipeline(vk::PipelineBindPoint::eCompute, **frame->pipeline);
    cb.bindDescriptorSets(vk::PipelineBindPoint::eCompute, layout, 0, frame->descriptors->get(), {});
    // The samples in dispatches of at most samples_per_dispatch, each continuing the last one's sums.
    for (tile.sample_begin = 0; tile.sample_begin < image.samples_per_pixel; tile.sample_begin = tile.sample_end) {
      tile.sample_end = std::min(image.samples_per_pixel, tile.sample_begin + samples_per_dispatch);
      if (tile.sample_begin > 0) {  // the last dispatch's sums are read by this one
        const vk::MemoryBarrier sums(vk::AccessFlagBits::eShaderWrite,
                                     vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
        cb.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                           sums, {}, {});
      }
      cb.pushConstants<TileConstants>(layout, vk::ShaderStageFlagBits::eCompute, 0, tile);
      cb.dispatch(groups_x, groups_y, 1);
    }
    // The shader's writes are read by the host after the fence.
    const vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
    cb.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
    cb.end();
    const vk::CommandBuffer raw = *cb;
    const vk::Fence fence = *frame->fences[tile_index % kSlots];
    ctx_->queue().submit(vk::SubmitInfo({}, {}, raw), fence);
    frame->in_flight.push_back(fence);  // reserved: cannot throw
  };
  // Waits for a tile, copies its pixels into the image and frees its slot.
  const auto finish = [&](uint32_t tile_index) {
    const vk::raii::Fence& fence = frame->fences[tile_index % kSlots];
    ctx_->wait(fence, request.tile_timeout, "a render tile");
    const auto read_start = Clock::now();
    std::erase(frame->in_flight, *fence);
    device.resetFences(*fence);
    frame->output.invalidate(device);
    const TileConstants tile = tile_at(tile_index);
    const auto* texels = static_cast<const glm::vec4*>(frame->output.mapped) + tile.output_offset;
    for (uint32_t y = 0; y < tile.height; ++y)
      for (uint32_t x = 0; x < tile.width; ++x) {
        const glm::vec4& texel = texels[size_t(y) * tile.width + x];
        result.at(tile.x0 + x, tile.y0 + y) = glm::vec3(texel);
        stats.rays += std::bit_cast<uint32_t>(texel.w);
      }
    readback_seconds += seconds_since(read_start);
    if (request.progress) request.progress(tile_index + 1, tile_count);
  };
  try {
    for (uint32_t tile_index = 0; tile_index < tile_count; ++tile_index) {
      submit(tile_index);
      if (tile_index > 0) finish(tile_index - 1);
      if (tile_index + 1 < tile_count && interrupt_requested()) throw Cancelled();
    }
    finish(tile_count - 1);
  } catch (...) {
    // Timed out, interrupted, or any other failure while a tile may still run: what it uses is kept
    // until the device is done with it (busy()), never destroyed under it.
    if (!frame->in_flight.empty()) abandoned_.push_back(std::move(frame));  // reserved: cannot throw
    throw;
  }
  // Reading back overlaps tracing: the trace is the whole span (so rays/s are not flattered), the
  // read back its own part of it.
  stats.trace_seconds = seconds_since(start);
  stats.readback_seconds = readback_seconds;
  stats.tiles = tile_count;
  if (stats_out) *stats_out = stats;
  return result;
}

uint32_t tile_side(const Scene& scene, const ImageSettings& image) {
  const double pixels = kTestsPerTile / (tests_per_sample(scene) * image.samples_per_pixel);
  const uint32_t side = static_cast<uint32_t>(std::sqrt(pixels)) / VKRAY_WORKGROUP_X * VKRAY_WORKGROUP_X;
  const uint32_t largest = (std::max(image.width, image.height) + VKRAY_WORKGROUP_X - 1) / VKRAY_WORKGROUP_X * VKRAY_WORKGROUP_X;
  return std::clamp<uint32_t>(side, VKRAY_WORKGROUP_X, largest);
}

}  // namespace vkray::gpu
