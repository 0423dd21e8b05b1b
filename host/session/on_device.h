// Work on the device whose lost device reaches the library's callers as vkray's DeviceLostError
// (base/errors.h), never as Vulkan-Hpp's vk::DeviceLostError.
#pragma once

#include <string>

#include <vulkan/vulkan_raii.hpp>

#include "base/errors.h"

namespace vkray {

template <typename Work>
auto on_device(Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const vk::DeviceLostError& e) {
    throw DeviceLostError(std::string(e.what()) + ": the device was lost");
  }
}

}  // namespace vkray
