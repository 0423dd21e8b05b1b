#include "session/failure.h"

#include <algorithm>
#include <new>
#include <string_view>

#include <vulkan/vulkan_raii.hpp>

namespace vkray {

namespace {

// Messages quote file names and text from the user's files: whatever a file held, what reaches a
// terminal is printable and of a readable length.
constexpr size_t kMaxLineLength = 1000;
constexpr size_t kMaxLines = 100;

Failure fit_to_print(Failure failure) {
  if (!failure.multiline) {
    failure.message = printable_middle(failure.message, kMaxLineLength);
    return failure;
  }
  std::string fitted;
  size_t lines = 0, at = 0;
  for (; at < failure.message.size() && lines < kMaxLines; ++lines) {
    const size_t end = std::min(failure.message.find('\n', at), failure.message.size());
    if (lines > 0) fitted += '\n';
    fitted += printable_middle(std::string_view(failure.message).substr(at, end - at), kMaxLineLength);
    at = end + 1;
  }
  if (at < failure.message.size()) fitted += "\n... (more lines left out)";
  failure.message = fitted;
  return failure;
}

Failure classify(const std::exception_ptr& error) {
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

}  // namespace

Failure describe_failure(const std::exception_ptr& error) { return fit_to_print(classify(error)); }

}  // namespace vkray
