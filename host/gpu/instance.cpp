#include "gpu/instance.h"

#include <algorithm>
#include <map>
#include <utility>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "base/errors.h"
#include "base/per_process.h"

namespace vkray::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::shared_ptr<Instance> make_instance(bool validation, const std::vector<std::string>& wanted) {
  auto result = std::make_shared<Instance>();
  const vk::raii::Context& context = result->context;
  if (context.enumerateInstanceVersion() < VK_API_VERSION_1_2)
    throw DeviceError("the Vulkan loader supports only Vulkan " + api_version_string(context.enumerateInstanceVersion()) +
                      "; vkray needs 1.2");
  std::vector<const char*> layers, extensions;
  if (validation) {
    const auto available = context.enumerateInstanceLayerProperties();
    if (std::none_of(available.begin(), available.end(),
                     [](const vk::LayerProperties& p) { return std::string_view(p.layerName) == kValidationLayer; }))
      throw DeviceError(std::string(kValidationLayer) +
                        " is not installed (Debian: apt-get install vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  const auto available = context.enumerateInstanceExtensionProperties();
  for (const std::string& name : wanted) {
    if (std::none_of(available.begin(), available.end(),
                     [&](const vk::ExtensionProperties& e) { return name == e.extensionName.data(); }))
      throw DeviceError("the Vulkan loader lacks the instance extension " + name + ", which a window needs");
    extensions.push_back(name.c_str());
  }
  const vk::ApplicationInfo app("vkray", 1, "vkray", 1, VK_API_VERSION_1_2);
  // Synchronization validation on top of the default checks: a missing barrier is a bug too.
  const vk::ValidationFeatureEnableEXT enables[] = {vk::ValidationFeatureEnableEXT::eSynchronizationValidation};
  const vk::ValidationFeaturesEXT features(enables);
  vk::InstanceCreateInfo info({}, &app, layers, extensions);
  if (validation) info.pNext = &features;
  result->instance = vk::raii::Instance(context, info);
  return result;
}

// The instances of this process. Never destroyed: destroying them in static teardown could race a
// device left running work (Context::abandon_work()), and nobody would read the validation layer's
// report then. A child made by fork() starts with none: the parent's instances came along without
// the driver's threads (lavapipe's compute threads, for one), so a device made from them waits for
// ever for its first submission; they are left as they are, never used nor destroyed there.
struct Instances {
  std::mutex mutex;  // a fresh one in a forked child: a parent's thread may have held this one
  // By validation and the extensions asked for: without and with validation for a headless device,
  // and the same for each window system's set (one, in a process with a window).
  std::map<std::pair<bool, std::vector<std::string>>, std::shared_ptr<Instance>> slots;
};
Instances& instances() {
  static PerProcess<Instances> all;
  return all.get();
}

}  // namespace

std::string api_version_string(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

std::shared_ptr<const Instance> shared_instance(bool validation, const std::vector<std::string>& extensions) {
  Instances& all = instances();
  const std::lock_guard lock(all.mutex);
  auto& slot = all.slots[{validation, extensions}];
  if (!slot) slot = make_instance(validation, extensions);
  return slot;
}

}  // namespace vkray::gpu
