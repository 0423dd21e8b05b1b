// What went wrong, as a face reports it: any exception that leaves the library, as one exit code and
// one message. vkray's own errors (base/errors.h) keep theirs; what a dependency throws is
// classified here, once for every face.
#pragma once

#include <exception>
#include <string>

#include "base/errors.h"

namespace vkray {

struct Failure {
  ExitCode exit_code;
  std::string headline;  // what kind of failure, for a person: "error", "device error", ...
  std::string message;   // what base/errors.h's messages say: the file and key, or the call and result
  bool multiline;        // the message has a line per problem (shader errors) and starts on its own line
};

// The failure `error` stands for: a vkray::Error by its kind; a Vulkan-Hpp vk::SystemError as a device
// error naming the call and its VkResult; std::bad_alloc as host memory exhausted (an input too large
// for this machine, exit 1); anything else as an internal error (exit 70).
Failure describe_failure(const std::exception_ptr& error);

}  // namespace vkray
