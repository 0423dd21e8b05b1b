// Vulkan buffers with their memory, and uploads into device-local memory.
#pragma once

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

namespace vkray::gpu {

struct Buffer {
  vk::raii::Buffer buffer{nullptr};
  vk::raii::DeviceMemory memory{nullptr};
  void* mapped = nullptr;  // persistently mapped when the memory is host-visible
  bool coherent = true;

  // Makes device writes visible to the host for non-coherent memory (no-op otherwise).
  void invalidate(const vk::raii::Device& device) const;
};

// `required` must hold; `preferred` is taken when some memory type has it.
Buffer create_buffer(const Context& ctx, vk::DeviceSize size, vk::BufferUsageFlags usage,
                     vk::MemoryPropertyFlags required, vk::MemoryPropertyFlags preferred = {});

// A device-local buffer holding `data`, written directly when that memory is host-visible (CPU and
// integrated devices) and through a staging copy otherwise. The data is visible to compute shaders
// submitted afterwards on the context's queue.
Buffer upload_buffer(const Context& ctx, const void* data, vk::DeviceSize size, vk::BufferUsageFlags usage);

}  // namespace vkray::gpu
