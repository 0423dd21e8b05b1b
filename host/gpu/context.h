// The Vulkan instance, the chosen physical device, the logical device and its compute queue, plus
// the validation layer's messages. Headless, unless asked for a window's surface (vkray view): then
// the queue can also draw and present to it, and the device has VK_KHR_swapchain.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/device_info.h"
#include "gpu/surface_request.h"

namespace vkray::gpu {

struct Instance;

// Messages from the Khronos validation layer. Shared, so that whoever made the Context can read it
// after the Context (whose destruction can itself produce messages, such as leaked objects) is gone.
class ValidationLog {
 public:
  void add(std::string message);
  std::vector<std::string> messages() const;
  size_t count() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

struct ContextOptions {
  std::string device;  // index or case-insensitive name substring; empty: best available
  // Where the Khronos validation layer's messages go (each is also printed to stderr); null: the
  // layer is off.
  std::shared_ptr<ValidationLog> validation_log;
  // A window to present to; null: headless.
  std::shared_ptr<const SurfaceRequest> surface;
};

class Context {
 public:
  explicit Context(const ContextOptions& options = {});

  const vk::raii::Instance& instance() const;  // the process's (gpu/instance.h), shared with other Contexts
  const vk::raii::Device& device() const { return device_; }
  const vk::raii::PhysicalDevice& physical_device() const { return physical_device_; }
  const vk::raii::Queue& queue() const { return queue_; }
  // The window's surface (ContextOptions::surface); null when headless.
  const vk::raii::SurfaceKHR& surface() const { return surface_; }
  uint32_t queue_family() const { return queue_family_; }
  const vk::PhysicalDeviceLimits& limits() const { return properties_.limits; }
  const std::string& device_name() const { return device_name_; }
  const std::string& driver_name() const { return driver_name_; }
  const DeviceInfo& info() const { return info_; }  // as `vkray devices` lists it, index included
  // Whether shaders may read the device clock (VK_KHR_shader_clock with shaderDeviceClock, and
  // shaderSubgroupClock where the device has it; GL_EXT_shader_realtime_clock, GL_ARB_shader_clock).
  bool has_device_clock() const { return has_device_clock_; }

  // Index of a memory type allowed by `type_bits` with all of `required` (and all of `preferred`
  // if such a type exists). Throws DeviceError if none has `required`.
  uint32_t memory_type(uint32_t type_bits, vk::MemoryPropertyFlags required,
                       vk::MemoryPropertyFlags preferred = {}) const;

  // Waits for a fence with a finite timeout; throws TimeoutError naming `what` on timeout, and
  // Cancelled on an interrupt request (base/interrupt.h). Either way the work may still run.
  void wait(const vk::raii::Fence& fence, std::chrono::milliseconds timeout, const char* what) const;

  // Says that work submitted to this device may still be running and will never be waited for
  // (what it uses has been left alive). The device is then not destroyed with the Context, and the
  // process must end with std::_Exit (work_left_running()).
  void abandon_work() const;
  ~Context();

 private:
  std::shared_ptr<ValidationLog> log_;
  mutable std::atomic<bool> work_abandoned_{false};
  // Declaration order is destruction order reversed: the messenger outlives the device.
  std::shared_ptr<const Instance> instance_;  // the process's (gpu/instance.h)
  vk::raii::DebugUtilsMessengerEXT messenger_{nullptr};
  vk::raii::SurfaceKHR surface_{nullptr};  // outlives the device, and the swapchains made on it
  vk::raii::PhysicalDevice physical_device_{nullptr};
  vk::PhysicalDeviceProperties properties_;
  DeviceInfo info_;
  std::string device_name_, driver_name_;
  uint32_t queue_family_ = 0;
  bool has_device_clock_ = false;
  vk::raii::Device device_{nullptr};
  vk::raii::Queue queue_{nullptr};
};

// Whether any Context of this process has abandoned work (Context::abandon_work()): exit handlers
// (the driver's own among them) could wait on it without end, so the process must end with
// std::_Exit.
bool work_left_running();

}  // namespace vkray::gpu
