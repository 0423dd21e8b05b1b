// The error types vkray raises, one per kind of failure, and the exit code each maps to.
#pragma once

#include <stdexcept>
#include <string>

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

}  // namespace vkray
