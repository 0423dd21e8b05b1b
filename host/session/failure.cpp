#include "session/failure.h"

#include <new>

#include <vulkan/vulkan_raii.hpp>

namespace vkray {

Failure describe_failure(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const Cancelled& e) {
    return {e.exit_code(), "interrupted; no image written", "", false};
  } catch (const ShaderError& e) {
    return {e.exit_code(), "shader compilation failed", e.what(), true};
  } catch (const DeviceError& e) {
    return {e.exit_code(), "device error", e.what(), false};
  } catch (const InternalError& e) {
    return {e.exit_code(), "internal error (a bug in vkray; please report it)", e.what(), false};
  } catch (const Error& e) {
    return {e.exit_code(), "error", e.what(), false};
  } catch (const vk::SystemError& e) {
    // Vulkan-Hpp's message names the call, e.g. "vk::raii::Device::createBuffer: ErrorOutOfDeviceMemory".
    return {kExitDevice, "Vulkan error", e.what(), false};
  } catch (const std::bad_alloc&) {
    return {kExitBadInput, "error", "out of host memory: the input is too large for this machine", false};
  } catch (const std::exception& e) {
    return {kExitInternal, "internal error (a bug in vkray; please report it)", e.what(), false};
  } catch (...) {
    return {kExitInternal, "internal error (a bug in vkray; please report it)", "an unknown exception", false};
  }
}

}  // namespace vkray
