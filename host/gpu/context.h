// The Vulkan instance, the chosen physical device, the logical device and its compute queue, plus
// the validation layer's messages. Headless: no surface, no swapchain.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

namespace vkray::gpu {

// Messages from the Khronos validation layer. Shared so a test can inspect it after the Context
// (whose destruction can itself produce messages, such as leaked objects) is gone.
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
  bool validation = false;  // enable VK_LAYER_KHRONOS_validation; any message is an error
  std::string device;       // index or case-insensitive name substring; empty: best available
  std::shared_ptr<ValidationLog> validation_log;  // where messages go; one is made if null
  bool echo_validation = true;                    // also print each message to stderr
};

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

class Context {
 public:
  explicit Context(const ContextOptions& options = {});

  const vk::raii::Device& device() const { return device_; }
  const vk::raii::PhysicalDevice& physical_device() const { return physical_device_; }
  const vk::raii::Queue& queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  const vk::PhysicalDeviceLimits& limits() const { return properties_.limits; }
  const std::string& device_name() const { return device_name_; }
  const std::string& driver_name() const { return driver_name_; }
  bool validation_enabled() const { return validation_; }
  ValidationLog& validation_log() { return *log_; }

  // Index of a memory type allowed by `type_bits` with all of `required` (and all of `preferred`
  // if such a type exists). Throws DeviceError if none has `required`.
  uint32_t memory_type(uint32_t type_bits, vk::MemoryPropertyFlags required,
                       vk::MemoryPropertyFlags preferred = {}) const;

  // Waits for a fence with a finite timeout; throws DeviceError naming `what` on timeout.
  void wait(const vk::raii::Fence& fence, std::chrono::milliseconds timeout, const char* what) const;

  // Throws DeviceError if the validation layer has reported anything since the last call.
  void check_validation(const char* during);

 private:
  bool validation_;
  std::shared_ptr<ValidationLog> log_;
  bool echo_;
  size_t validation_seen_ = 0;
  std::pair<ValidationLog*, bool> callback_data_{nullptr, true};  // the messenger's user data
  // Declaration order is destruction order reversed: the messenger outlives the device.
  vk::raii::Context context_;
  vk::raii::Instance instance_{nullptr};
  vk::raii::DebugUtilsMessengerEXT messenger_{nullptr};
  vk::raii::PhysicalDevice physical_device_{nullptr};
  vk::PhysicalDeviceProperties properties_;
  std::string device_name_, driver_name_;
  uint32_t queue_family_ = 0;
  vk::raii::Device device_{nullptr};
  vk::raii::Queue queue_{nullptr};
};

}  // namespace vkray::gpu
