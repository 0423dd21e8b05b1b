// Intel Embree 3 tracing the same rays as vkray, for `vkray bench`: the CPU raytracer a user would
// otherwise pick, used the way its documentation recommends for coherent rays (8-wide packets).
#pragma once

#include <cstdint>
#include <memory>

#include "scene/scene.h"

namespace vkray::bench {

class EmbreeTracer {
 public:
  // Builds Embree's BVH on `threads` threads (timed: build_seconds()).
  EmbreeTracer(const Scene& scene, unsigned threads);
  ~EmbreeTracer();
  EmbreeTracer(const EmbreeTracer&) = delete;
  EmbreeTracer& operator=(const EmbreeTracer&) = delete;

  double build_seconds() const { return build_seconds_; }
  static const char* version();  // "3.13.5"

  struct Result {
    uint64_t rays = 0;  // camera rays + shadow rays
    uint64_t hits = 0;  // camera rays that hit something
    double seconds = 0;
  };
  // The scene's camera rays at pixel centres (1 sample per pixel), in 2 x 4 pixel packets
  // (rtcIntersect8), and when `shadows`, one shadow ray per hit and light facing it
  // (rtcOccluded8), on `threads` threads.
  Result trace(uint32_t width, uint32_t height, bool shadows, unsigned threads) const;

 private:
  struct State;
  std::unique_ptr<State> state_;
  const Scene& scene_;
  double build_seconds_ = 0;
};

}  // namespace vkray::bench
