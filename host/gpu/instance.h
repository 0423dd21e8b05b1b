// The process's Vulkan instances: one with the Khronos validation layer, one without, each created
// by the first Context (or device listing) that needs it and kept until the process ends. Each
// validated Context has its own messenger on the shared instance, so sessions open at the same time
// each see the validation messages of all of them (tests and commands open one at a time).
//
// Why not one per Context: the loader loads the driver with the first instance and unloads it with
// the last, so a process that opens device after device (the test binary, a Python loop, `vkray
// check`) loads and unloads the driver each time. NVIDIA's driver (580.159.04, H100) stopped creating
// instances after about 60 such cycles in one process (vkCreateInstance: ErrorIncompatibleDriver,
// for every test after that), and other projects report the same driver corrupting state over
// repeated instance cycles. Devices are still created and destroyed per Context.
//
// A child made by fork() makes instances of its own: the parent's came along without the driver's
// threads, and a device made from them would wait for ever for its first submission. A Context the
// parent opened is of no use in the child (its device is the parent's) and must not be destroyed
// there either: the driver would wait for threads that are not there.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

namespace vkray::gpu {

struct Instance {
  vk::raii::Context context;  // the loader's entry points: declared first, destroyed last
  vk::raii::Instance instance{nullptr};
};

// The instance for `validation` (VK_LAYER_KHRONOS_validation with synchronization validation and
// VK_EXT_debug_utils, or neither), with `extensions` besides (a window system's, for a surface: one
// instance for each set asked for). Throws DeviceError when the loader is older than Vulkan 1.2, or
// the layer or an extension is missing; a later call tries again. Thread-safe; in a forked child, the
// child's own.
std::shared_ptr<const Instance> shared_instance(bool validation, const std::vector<std::string>& extensions = {});

// A Vulkan version number as "1.3.230".
std::string api_version_string(uint32_t version);

}  // namespace vkray::gpu
