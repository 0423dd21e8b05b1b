// Size arithmetic that cannot wrap: every count-times-size that reaches an allocation goes through
// these. The scene's own caps (image side 16384, 65536 samples, 2^27 primitives) keep real inputs
// far from 2^64; these make overflow impossible by construction rather than by those caps alone.
#pragma once

#include <cstdint>
#include <string>

#include "base/errors.h"

namespace vkray {

// a * b, or LimitError (exit 1) naming `what` when the product does not fit in 64 bits.
inline uint64_t checked_mul(uint64_t a, uint64_t b, const char* what) {
  uint64_t product = 0;
  if (__builtin_mul_overflow(a, b, &product)) throw LimitError(std::string(what) + ": size overflows 64 bits");
  return product;
}

// a + b, likewise.
inline uint64_t checked_add(uint64_t a, uint64_t b, const char* what) {
  uint64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum)) throw LimitError(std::string(what) + ": size overflows 64 bits");
  return sum;
}

}  // namespace vkray
