#include "gpu/buffer.h"

#include <chrono>
#include <cstring>

#include "base/errors.h"

namespace vkray::gpu {

void Buffer::invalidate(const vk::raii::Device& device) const {
  if (!coherent && mapped) device.invalidateMappedMemoryRanges(vk::MappedMemoryRange(*memory, 0, VK_WHOLE_SIZE));
}

Buffer create_buffer(const Context& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                     vk::MemoryPropertyFlags required, vk::MemoryPropertyFlags preferred) {
  Buffer b;
  b.buffer = vk::raii::Buffer(ctx.device(), vk::BufferCreateInfo({}, size, usage, vk::SharingMode::eExclusive));
  const vk::MemoryRequirements req = b.buffer.getMemoryRequirements();
  const uint32_t type = ctx.memory_type(req.memoryTypeBits, required, preferred);
  b.memory = vk::raii::DeviceMemory(ctx.device(), vk::MemoryAllocateInfo(req.size, type));
  b.buffer.bindMemory(*b.memory, 0);
  const auto flags = ctx.physical_device().getMemoryProperties().memoryTypes[type].propertyFlags;
  if (flags & vk::MemoryPropertyFlagBits::eHostVisible) {
    b.mapped = b.memory.mapMemory(0, VK_WHOLE_SIZE);
    b.coherent = static_cast<bool>(flags & vk::MemoryPropertyFlagBits::eHostCoherent);
  }
  return b;
}

Buffer upload_buffer(const Context& ctx, const void* data, vk::DeviceSize size, vk::BufferUsageFlags usage) {
  using M = vk::MemoryPropertyFlagBits;
  Buffer target = create_buffer(ctx, size, usage | vk::BufferUsageFlagBits::eTransferDst, M::eDeviceLocal);
  if (target.mapped) {
    std::memcpy(target.mapped, data, size);
    if (!target.coherent) ctx.device().flushMappedMemoryRanges(vk::MappedMemoryRange(*target.memory, 0, VK_WHOLE_SIZE));
    return target;  // host writes are made visible to the device by the later vkQueueSubmit
  }
  Buffer staging = create_buffer(ctx, size, vk::BufferUsageFlagBits::eTransferSrc, M::eHostVisible | M::eHostCoherent);
  std::memcpy(staging.mapped, data, size);

  vk::raii::CommandPool pool(ctx.device(), {vk::CommandPoolCreateFlagBits::eTransient, ctx.queue_family()});
  vk::raii::CommandBuffers cbs(ctx.device(), {*pool, vk::CommandBufferLevel::ePrimary, 1});
  const vk::raii::CommandBuffer& cb = cbs[0];
  cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  cb.copyBuffer(*staging.buffer, *target.buffer, vk::BufferCopy(0, 0, size));
  // Later submissions read the buffer from compute shaders.
  const vk::MemoryBarrier barrier(vk::AccessFlagBits::eTransferWrite,
                                  vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eUniformRead);
  cb.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, barrier, {}, {});
  cb.end();
  vk::raii::Fence fence(ctx.device(), vk::FenceCreateInfo{});
  const vk::CommandBuffer raw = *cb;
  ctx.queue().submit(vk::SubmitInfo({}, {}, raw), *fence);
  try {
    ctx.wait(fence, std::chrono::seconds(60), "a buffer upload");
  } catch (...) {  // timed out or interrupted
    // The copy may still run: leave everything it uses to the process (Context::abandon_work()).
    for (auto* buffer : {&staging, &target}) {
      static_cast<void>(buffer->buffer.release());
      static_cast<void>(buffer->memory.release());
    }
    for (auto& command_buffer : cbs) static_cast<void>(command_buffer.release());
    static_cast<void>(pool.release());
    static_cast<void>(fence.release());
    ctx.abandon_work();
    throw;
  }
  return target;
}

}  // namespace vkray::gpu
