// What `vkray devices` reports of each Vulkan device: plain data, no Vulkan headers, so that a face
// can list devices without knowing Vulkan.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace vkray::gpu {

struct DeviceInfo {
  uint32_t index;
  std::string name;
  std::string type;  // "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other"
  std::string driver;
  std::string api_version;
  bool has_compute_queue;
  uint32_t max_workgroup_invocations;
  uint32_t max_texel_buffer_elements;
  uint64_t max_storage_buffer_range;
  uint64_t device_local_bytes;
};

// Every Vulkan device the loader reports, in loader order (the INDEX of --device).
std::vector<DeviceInfo> list_devices();

}  // namespace vkray::gpu
