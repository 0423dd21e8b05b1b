// How many threads vkray's CPU work uses when the user names no number: one per hardware thread.
#pragma once

#include <algorithm>
#include <thread>

namespace vkray {

// `requested`, or one per hardware thread (at least one) when it is 0.
inline unsigned thread_count(unsigned requested = 0) {
  return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace vkray
