#include "gpu/accumulator.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include "base/errors.h"
#include "base/timing.h"
#include "gpu/renderer.h"
#include "packing/scene_packing.h"
#include "shared/first_hit_layout.h"
#include "shared/types.h"

namespace vkray::gpu {
namespace {

// How long the destructor waits for a step still on the device before leaving it to the process.
constexpr std::chrono::milliseconds kTeardownWait{60000};

}  // namespace

Accumulator::Accumulator(std::shared_ptr<const Context> ctx, std::shared_ptr<const TracePipeline> trace_pipeline,
                         std::shared_ptr<const SceneBuffers> scene, const ImageSettings& image, const ShaderVariant& variant)
    : ctx_(std::move(ctx)), trace_pipeline_(std::move(trace_pipeline)), scene_(std::move(scene)), image_(image) {
  aovs_ = variant.aovs;
  const uint64_t pixels = uint64_t(image.width) * image.height;
  const uint64_t bytes = pixels * (aovs_ ? sizeof(FirstHitTexels) : sizeof(glm::vec4));  // the larger
  if (bytes > ctx_->limits().maxStorageBufferRange)
    throw DeviceError("a " + std::to_string(image.width) + " x " + std::to_string(image.height) + " image's sums (" +
                      std::to_string(bytes) + " bytes) do not fit one storage buffer of " + ctx_->device_name() +
                      " (maxStorageBufferRange " + std::to_string(ctx_->limits().maxStorageBufferRange) + ")");
  pipeline_ = trace_pipeline_->pipeline(variant);
  samples_per_dispatch_ = samples_in_one_dispatch(scene_->scene(), variant);
  const FrameUniforms frame = pack_frame(scene_->scene(), scene_->primitive_count(), scene_->lighting(), image);
  uniforms_ = upload_buffer(*ctx_, &frame, sizeof(frame), vk::BufferUsageFlagBits::eUniformBuffer);
  using M = vk::MemoryPropertyFlagBits;
  output_ = create_buffer(*ctx_, pixels * sizeof(glm::vec4), vk::BufferUsageFlagBits::eStorageBuffer, M::eHostVisible,
                          M::eHostCached);
  aov_output_ = create_buffer(*ctx_, (aovs_ ? pixels : 1) * sizeof(FirstHitTexels), vk::BufferUsageFlagBits::eStorageBuffer,
                              M::eHostVisible, M::eHostCached);
  DescriptorWriter writer = trace_pipeline_->descriptors().writer();
  writer.buffer(VKRAY_BINDING_FRAME, *uniforms_.buffer).buffer(VKRAY_BINDING_OUTPUT, *output_.buffer);
  writer.buffer(VKRAY_BINDING_AOVS, *aov_output_.buffer);
  scene_->bind(writer);
  descriptors_ = writer.write();
  const vk::raii::Device& device = ctx_->device();
  command_pool_ = vk::raii::CommandPool(device, {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx_->queue_family()});
  command_buffer_ = std::move(vk::raii::CommandBuffers(device, {*command_pool_, vk::CommandBufferLevel::ePrimary, 1})[0]);
  fence_ = vk::raii::Fence(device, vk::FenceCreateInfo{});
}

Accumulator::~Accumulator() {
  if (!in_flight_) return;
  try {
    if (ctx_->device().waitForFences({*fence_}, VK_TRUE, uint64_t(std::chrono::nanoseconds(kTeardownWait).count())) ==
        vk::Result::eSuccess)
      return;
  } catch (const vk::DeviceLostError&) {
    return;  // nothing runs on a lost device
  } catch (...) {
  }
  // Still running: what it uses is never destroyed under it.
  static_cast<void>(output_.buffer.release());
  static_cast<void>(output_.memory.release());
  static_cast<void>(aov_output_.buffer.release());
  static_cast<void>(aov_output_.memory.release());
  static_cast<void>(command_buffer_.release());
  static_cast<void>(command_pool_.release());
  static_cast<void>(fence_.release());
  ctx_->abandon_work();
}

double Accumulator::submit_and_wait(const AccumulationStep& step, uint32_t samples_per_dispatch,
                                    std::chrono::milliseconds timeout) {
  TileConstants tile{};
  tile.x0 = 0;
  tile.y0 = step.y0;
  tile.width = image_.width;
  tile.height = step.y1 - step.y0;
  tile.row_stride = row_stride((tile.height + VKRAY_WORKGROUP_Y - 1) / VKRAY_WORKGROUP_Y);
  tile.output_offset = step.y0 * image_.width;  // the sums hold the whole image
  tile.probe_iterations = 2;
  const vk::PipelineLayout layout = *trace_pipeline_->layout();
  const vk::raii::CommandBuffer& cb = command_buffer_;
  cb.reset();
  cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  // The host wrote the sums back (a step cut short) or read them: its accesses come first.
  const vk::MemoryBarrier from_host(vk::AccessFlagBits::eHostWrite | vk::AccessFlagBits::eHostRead,
                                    vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
  cb.pipelineBarrier(vk::PipelineStageFlagBits::eHost, vk::PipelineStageFlagBits::eComputeShader, {}, from_host, {}, {});
  cb.bindPipeline(vk::PipelineBindPoint::eCompute, **pipeline_);
  cb.bindDescriptorSets(vk::PipelineBindPoint::eCompute, layout, 0, descriptors_->get(), {});
  record_sample_dispatches(cb, layout, tile, step.sample_begin, step.sample_end, samples_per_dispatch);
  cb.end();
  const auto start = Clock::now();
  const vk::CommandBuffer raw = *cb;
  ctx_->queue().submit(vk::SubmitInfo({}, {}, raw), *fence_);
  in_flight_ = true;
  ctx_->wait(fence_, timeout, "an accumulation step");  // throws with the step still in flight
  in_flight_ = false;
  ctx_->device().resetFences(*fence_);
  return seconds_since(start);
}

bool Accumulator::rows_complete(uint32_t y0, uint32_t y1, uint64_t* rays) const {
  output_.invalidate(ctx_->device());
  const auto* texels = static_cast<const glm::vec4*>(output_.mapped);
  uint32_t cut_short = 0;
  uint64_t total = 0;
  for (size_t i = size_t(y0) * image_.width; i < size_t(y1) * image_.width; ++i) {
    const uint32_t count = std::bit_cast<uint32_t>(texels[i].w);
    cut_short |= count & VKRAY_LOOPS_CUT_SHORT;
    total += count;
  }
  if (cut_short) return false;
  *rays = total;
  return true;
}

double Accumulator::trace(const AccumulationStep& step, std::chrono::milliseconds timeout) {
  if (step.y0 >= step.y1 || step.y1 > image_.height || step.sample_begin >= step.sample_end ||
      step.sample_end > image_.samples_per_pixel)
    throw InternalError("an accumulation step of rows " + std::to_string(step.y0) + ".." + std::to_string(step.y1) +
                        ", samples " + std::to_string(step.sample_begin) + ".." + std::to_string(step.sample_end));
  // The rows as they are, to put back if the driver cuts the step's loops short; their rays so far.
  const size_t first = size_t(step.y0) * image_.width, count = size_t(step.y1 - step.y0) * image_.width;
  output_.invalidate(ctx_->device());
  const auto* texels = static_cast<glm::vec4*>(output_.mapped);
  saved_.assign(texels + first, texels + first + count);
  if (aovs_) {
    aov_output_.invalidate(ctx_->device());
    const auto* first_hits = static_cast<const FirstHitTexels*>(aov_output_.mapped);
    saved_aovs_.assign(first_hits + first, first_hits + first + count);
  }
  uint64_t rays_before = 0;
  if (step.sample_begin > 0)
    for (const glm::vec4& t : saved_) rays_before += std::bit_cast<uint32_t>(t.w);
  double seconds = 0;
  for (;;) {
    seconds += submit_and_wait(step, samples_per_dispatch_, timeout);
    uint64_t rays_after = 0;
    if (rows_complete(step.y0, step.y1, &rays_after)) {
      rays_ += rays_after - rays_before;
      return seconds;
    }
    if (samples_per_dispatch_ == 1)
      throw DeviceError(ctx_->device_name() + " cut the shader's loops short within one sample of a pixel (llvmpipe "
                        "stops an invocation after 65535 loop iterations): the scene needs more than that");
    samples_per_dispatch_ = std::max(1u, samples_per_dispatch_ / 2);
    std::memcpy(static_cast<glm::vec4*>(output_.mapped) + first, saved_.data(), count * sizeof(glm::vec4));
    if (!output_.coherent)
      ctx_->device().flushMappedMemoryRanges(vk::MappedMemoryRange(*output_.memory, 0, VK_WHOLE_SIZE));
    if (aovs_) {
      std::memcpy(static_cast<FirstHitTexels*>(aov_output_.mapped) + first, saved_aovs_.data(), count * sizeof(FirstHitTexels));
      if (!aov_output_.coherent)
        ctx_->device().flushMappedMemoryRanges(vk::MappedMemoryRange(*aov_output_.memory, 0, VK_WHOLE_SIZE));
    }
  }
}

void Accumulator::read(uint32_t y0, uint32_t y1, Image& sums) const {
  if (sums.width != image_.width || sums.height != image_.height || y1 > image_.height)
    throw InternalError("an accumulation read into an image of another size");
  output_.invalidate(ctx_->device());
  const auto* texels = static_cast<const glm::vec4*>(output_.mapped);
  const RadianceUnscale unscale(scene_->lighting().radiance_exponent);
  for (size_t i = size_t(y0) * image_.width; i < size_t(y1) * image_.width; ++i) sums.pixels[i] = unscale(glm::vec3(texels[i]));
}

void Accumulator::read_aovs(uint32_t y0, uint32_t y1, Aovs& aovs) const {
  if (!aovs_ || aovs.width != image_.width || aovs.height != image_.height || y1 > image_.height)
    throw InternalError("an accumulation's first-hit passes read without passes, or into passes of another size");
  aov_output_.invalidate(ctx_->device());
  const auto* first_hits = static_cast<const FirstHitTexels*>(aov_output_.mapped);
  for (uint32_t y = y0; y < y1; ++y)
    for (uint32_t x = 0; x < image_.width; ++x) aovs.set(x, y, first_hit_sums(first_hits[size_t(y) * image_.width + x]));
}

}  // namespace vkray::gpu
