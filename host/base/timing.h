// Wall-clock timing: the phases a render reports, and the phase lines vkray prints.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace vkray {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

inline double seconds_between(Clock::time_point start, Clock::time_point end) {
  return std::chrono::duration<double>(end - start).count();
}

// "0.27 ms", "8.5 ms", "123 ms": about three significant digits.
inline std::string format_ms(double ms) {
  char text[32];
  std::snprintf(text, sizeof text, ms < 1 ? "%.2f ms" : ms < 10 ? "%.1f ms" : "%.0f ms", ms);
  return text;
}

}  // namespace vkray
