// The error types vkray raises, one per kind of failure, and the exit code each maps to.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace vkray {

// Process exit codes; documented in `vkray --help` and the README.
enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 1,  // scene, mesh, shader or output file
  kExitUsage = 2,     // command line
  kExitDevice = 3,    // Vulkan or device failure
};

// A mistake in something the user gave us. The message names the file and the key or line.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct SceneError : InputError {
  using InputError::InputError;
};
struct MeshError : InputError {
  using InputError::InputError;
};
struct ShaderError : InputError {
  using InputError::InputError;
};
struct OutputError : InputError {
  using InputError::InputError;
};

// Vulkan or the device failed: no device, an API call failed, a fence timed out, a validation message.
struct DeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Text from a user's file, fit to quote in a one-line message: control and non-ASCII bytes become
// '?', and long text is shortened.
inline std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 60)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (text.size() > 60) out += "...";
  return out;
}

}  // namespace vkray
