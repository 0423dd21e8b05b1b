// Invariants of vkray's own code, stated where they are established (pbrt-v4's CHECK): a BVH or a
// packed node that breaks one fails when it is built, naming the condition, not as a wrong pixel.
#pragma once

#include <string>

#include "base/errors.h"

namespace vkray {

[[noreturn]] inline void invariant_failed(const char* condition, const std::string& what, const char* file, int line) {
  throw InternalError(std::string(file) + ":" + std::to_string(line) + ": " + what + " (" + condition + " does not hold)");
}

}  // namespace vkray

// Throws InternalError when `condition` is false; `what` says what went wrong in words.
#define VKRAY_CHECK(condition, what)                                                 \
  do {                                                                               \
    if (!(condition)) ::vkray::invariant_failed(#condition, what, __FILE__, __LINE__); \
  } while (false)
