#include "gpu/context.h"

#include <algorithm>
#include <cctype>
#include <iostream>
#include <optional>
#include <string_view>

#include "base/errors.h"
#include "base/interrupt.h"
#include "gpu/instance.h"

namespace vkray::gpu {
namespace {

std::atomic<bool> g_work_left_running{false};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

std::string type_name(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return "discrete GPU";
    case vk::PhysicalDeviceType::eIntegratedGpu: return "integrated GPU";
    case vk::PhysicalDeviceType::eVirtualGpu: return "virtual GPU";
    case vk::PhysicalDeviceType::eCpu: return "CPU";
    default: return "other";
  }
}

// Lower is better: discrete, then integrated, then virtual, then CPU (lavapipe).
int type_rank(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return 0;
    case vk::PhysicalDeviceType::eIntegratedGpu: return 1;
    case vk::PhysicalDeviceType::eVirtualGpu: return 2;
    case vk::PhysicalDeviceType::eCpu: return 3;
    default: return 4;
  }
}

// A family that computes; with a surface, one that also draws (the viewer's overlay) and presents
// to it (every desktop driver has one: the first family, as a rule).
std::optional<uint32_t> compute_queue_family(const vk::raii::PhysicalDevice& pd, const vk::raii::SurfaceKHR* surface = nullptr) {
  const auto families = pd.getQueueFamilyProperties();
  for (uint32_t i = 0; i < families.size(); ++i) {
    if (!(families[i].queueFlags & vk::QueueFlagBits::eCompute)) continue;
    if (surface && (!(families[i].queueFlags & vk::QueueFlagBits::eGraphics) || !pd.getSurfaceSupportKHR(i, **surface)))
      continue;
    return i;
  }
  return std::nullopt;
}

// The clock features to enable: both of the device's when it can read the device clock (shaders
// may then read it: tests make a tile slow with it, tests/support/slow_shaders.h), else none.
std::optional<vk::PhysicalDeviceShaderClockFeaturesKHR> shader_clock(const vk::raii::PhysicalDevice& pd) {
  const auto extensions = pd.enumerateDeviceExtensionProperties();
  if (std::none_of(extensions.begin(), extensions.end(), [](const vk::ExtensionProperties& e) {
        return std::string_view(e.extensionName) == VK_KHR_SHADER_CLOCK_EXTENSION_NAME;
      }))
    return std::nullopt;
  const auto chain = pd.getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceShaderClockFeaturesKHR>();
  vk::PhysicalDeviceShaderClockFeaturesKHR clock = chain.get<vk::PhysicalDeviceShaderClockFeaturesKHR>();
  if (!clock.shaderDeviceClock) return std::nullopt;
  clock.pNext = nullptr;
  return clock;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::string message = std::string("validation ") + level + ": " + (data->pMessage ? data->pMessage : "");
  std::cerr << "vkray: " << message << "\n";
  static_cast<ValidationLog*>(user)->add(std::move(message));
  return VK_FALSE;  // never abort the call: we report, then fail at the next check
}

DeviceInfo describe_device(const vk::raii::PhysicalDevice& pd, uint32_t index) {
  const auto chain = pd.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceDriverProperties>();
  const auto& props = chain.get<vk::PhysicalDeviceProperties2>().properties;
  const auto& driver = chain.get<vk::PhysicalDeviceDriverProperties>();
  uint64_t local = 0;
  const auto memory = pd.getMemoryProperties();
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & vk::MemoryHeapFlagBits::eDeviceLocal) local += memory.memoryHeaps[h].size;
  return {index, props.deviceName.data(), type_name(props.deviceType),
          std::string(driver.driverName.data()) + " " + driver.driverInfo.data(), api_version_string(props.apiVersion),
          compute_queue_family(pd).has_value(), props.limits.maxComputeWorkGroupInvocations,
          props.limits.maxTexelBufferElements, props.limits.maxStorageBufferRange, local};
}

}  // namespace

void ValidationLog::add(std::string message) {
  std::lock_guard lock(mutex_);
  messages_.push_back(std::move(message));
}
std::vector<std::string> ValidationLog::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}
size_t ValidationLog::count() const {
  std::lock_guard lock(mutex_);
  return messages_.size();
}

std::vector<DeviceInfo> list_devices() {
  const auto instance = shared_instance(false);
  std::vector<DeviceInfo> result;
  const vk::raii::PhysicalDevices devices(instance->instance);
  for (uint32_t i = 0; i < devices.size(); ++i) result.push_back(describe_device(devices[i], i));
  return result;
}

Context::Context(const ContextOptions& options)
    : log_(options.validation_log),
      instance_(shared_instance(log_ != nullptr, options.surface ? options.surface->instance_extensions : std::vector<std::string>{})) {
  if (log_) {
    using S = vk::DebugUtilsMessageSeverityFlagBitsEXT;
    using T = vk::DebugUtilsMessageTypeFlagBitsEXT;
    messenger_ = vk::raii::DebugUtilsMessengerEXT(
        instance_->instance, vk::DebugUtilsMessengerCreateInfoEXT({}, S::eWarning | S::eError,
                                                        T::eGeneral | T::eValidation | T::ePerformance,
                                                        &on_validation_message, log_.get()));
  }

  if (options.surface) surface_ = vk::raii::SurfaceKHR(instance_->instance, options.surface->create(*instance_->instance));
  const vk::raii::SurfaceKHR* surface = options.surface ? &surface_ : nullptr;

  // ---- choose the physical device ----
  vk::raii::PhysicalDevices devices(instance_->instance);
  if (devices.empty()) throw DeviceError("no Vulkan device found (install mesa-vulkan-drivers for lavapipe)");
  std::optional<size_t> chosen;
  if (!options.device.empty()) {
    const bool is_index = std::all_of(options.device.begin(), options.device.end(), ::isdigit);
    for (size_t i = 0; i < devices.size() && !chosen; ++i) {
      const std::string name = devices[i].getProperties().deviceName.data();
      if (is_index ? std::to_string(i) == options.device : lower(name).find(lower(options.device)) != std::string::npos)
        chosen = i;
    }
    if (!chosen) {
      std::string names;
      for (size_t i = 0; i < devices.size(); ++i)
        names += (i ? ", " : " ") + std::to_string(i) + ": " + devices[i].getProperties().deviceName.data();
      // One line: a face prints a device error's message on one line.
      throw DeviceError("no Vulkan device matches --device \"" + options.device + "\"; available:" + names);
    }
    if (!compute_queue_family(devices[*chosen], surface))
      throw DeviceError(std::string(devices[*chosen].getProperties().deviceName.data()) +
                        (surface ? " has no queue that computes, draws and presents to the window" : " has no compute queue"));
  } else {
    for (size_t i = 0; i < devices.size(); ++i) {
      if (!compute_queue_family(devices[i], surface) || devices[i].getProperties().apiVersion < VK_API_VERSION_1_2) continue;
      if (!chosen || type_rank(devices[i].getProperties().deviceType) <
                         type_rank(devices[*chosen].getProperties().deviceType))
        chosen = i;
    }
    if (!chosen)
      throw DeviceError(surface ? "no Vulkan 1.2 device can both compute and present to the window"
                                : "no Vulkan 1.2 device with a compute queue found");
  }
  info_ = describe_device(devices[*chosen], uint32_t(*chosen));
  physical_device_ = std::move(devices[*chosen]);
  const auto chain = physical_device_.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceDriverProperties>();
  properties_ = chain.get<vk::PhysicalDeviceProperties2>().properties;
  device_name_ = properties_.deviceName.data();
  driver_name_ = chain.get<vk::PhysicalDeviceDriverProperties>().driverName.data();
  queue_family_ = *compute_queue_family(physical_device_, surface);

  // ---- logical device and queue ----
  const float priority = 1.0f;
  const vk::DeviceQueueCreateInfo queue_info({}, queue_family_, 1, &priority);
  std::vector<const char*> extensions;
  vk::StructureChain<vk::DeviceCreateInfo, vk::PhysicalDeviceShaderClockFeaturesKHR> device_info;
  device_info.get<vk::DeviceCreateInfo>().setQueueCreateInfos(queue_info);
  if (const auto clock = shader_clock(physical_device_)) {
    extensions.push_back(VK_KHR_SHADER_CLOCK_EXTENSION_NAME);
    device_info.get<vk::PhysicalDeviceShaderClockFeaturesKHR>() = *clock;
    has_device_clock_ = true;
  } else {
    device_info.unlink<vk::PhysicalDeviceShaderClockFeaturesKHR>();
  }
  if (surface) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  device_info.get<vk::DeviceCreateInfo>().setPEnabledExtensionNames(extensions);
  device_ = vk::raii::Device(physical_device_, device_info.get<vk::DeviceCreateInfo>());
  queue_ = vk::raii::Queue(device_, queue_family_, 0);
}

const vk::raii::Instance& Context::instance() const { return instance_->instance; }

Context::~Context() {
  if (!work_abandoned_) return;
  // Work may still run on the device: leave the device to the process instead of destroying it
  // under the work. The messenger is destroyed as usual (no device work uses it, and left on the
  // process's instance it would report to a log that is gone); the instance is never destroyed.
  static_cast<void>(device_.release());
}

void Context::abandon_work() const {
  work_abandoned_ = true;
  g_work_left_running = true;
}

bool work_left_running() { return g_work_left_running; }

uint32_t Context::memory_type(uint32_t type_bits, vk::MemoryPropertyFlags required,
                              vk::MemoryPropertyFlags preferred) const {
  const auto memory = physical_device_.getMemoryProperties();
  std::optional<uint32_t> fallback;
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    const auto flags = memory.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (!fallback) fallback = i;
  }
  if (!fallback) throw DeviceError("no Vulkan memory type with " + vk::to_string(required) + " on " + device_name_);
  return *fallback;
}

void Context::wait(const vk::raii::Fence& fence, std::chrono::milliseconds timeout, const char* what) const {
  // In slices, so that a Ctrl-C is seen within one even while a long tile runs.
  constexpr auto kSlice = std::chrono::milliseconds(50);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    throw_if_interrupted();
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - std::chrono::steady_clock::now());
    const auto slice = std::clamp(left, std::chrono::nanoseconds(0), std::chrono::nanoseconds(kSlice));
    if (device_.waitForFences({*fence}, VK_TRUE, uint64_t(slice.count())) != vk::Result::eTimeout) return;
    if (slice < kSlice) break;
  }
  throw TimeoutError(std::string("vkWaitForFences: ") + what + " did not finish within " +
                       std::to_string(timeout.count()) + " ms (VK_TIMEOUT)");
}

}  // namespace vkray::gpu
