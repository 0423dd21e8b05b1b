// How many threads vkray's CPU work uses when the user names no number (one per hardware thread),
// and the most a user may name.
#pragma once

#include <algorithm>
#include <thread>

namespace vkray {

// The most threads a caller may ask for (`--threads`, threads=): more is a mistake, not a machine,
// and each is a thread started.
constexpr unsigned kMaxThreads = 256;

// `requested`, or one per hardware thread (at least one) when it is 0.
inline unsigned thread_count(unsigned requested = 0) {
  return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace vkray
