// What a device that shows its images in a window needs from the window system (vkray view): the
// instance extensions for its surfaces, and the surface made on the instance. Kept apart from
// gpu/context.h so that the library's options can name it without Vulkan-Hpp.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <vulkan/vulkan_core.h>

namespace vkray::gpu {

struct SurfaceRequest {
  std::vector<std::string> instance_extensions;  // VK_KHR_surface and the platform's own
  // Makes the window's surface on `instance`; throws DeviceError when it cannot.
  std::function<VkSurfaceKHR(VkInstance instance)> create;
};

}  // namespace vkray::gpu
