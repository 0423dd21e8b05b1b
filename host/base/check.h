// Invariants of vkray's own code, stated where they are established (pbrt-v4's CHECK): a BVH or a
// packed node that breaks one fails when it is built, naming the condition, not as a wrong pixel.
#pragma once

#include <source_location>
#include <string>

#include "base/errors.h"

namespace vkray {

[[noreturn]] inline void invariant_failed(const char* condition, const std::string& what,
                                          std::source_location where = std::source_location::current()) {
  throw InternalError(std::string(where.file_name()) + ":" + std::to_string(where.line()) + ": " + what + " (" +
                      condition + " does not hold)");
}

}  // namespace vkray

// Throws InternalError when `condition` is false; `what` says what went wrong in words.
#define VKRAY_CHECK(condition, what) \
  do {                               \
    if (!(condition)) ::vkray::invariant_failed(#condition, what); \
  } while (false)
