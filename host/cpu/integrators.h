// The CPU reference's two integrators: the radiance one camera ray brings, by the direct model or by
// path tracing (docs/rendering.md). Each draws from the sample's stream exactly as the
// shader does (shaders/direct.glsl, shaders/path.glsl), so that both trace the same paths.
#pragma once

#include <cstdint>

#include "cpu/lights.h"
#include "image/aovs.h"
#include "cpu/tracer.h"

namespace vkray::cpu {

struct SampleState {
  uint32_t stream;     // the sample's random numbers (shared/sampling.h)
  uint64_t signature;  // what the camera ray saw: its primitive and the point lights lighting it
  uint64_t rays = 0;   // every ray traced, the camera ray included by the caller
  // Where the camera ray's hit is added for the first-hit passes (image/aovs.h); null: not asked for.
  FirstHitSums* first_hit = nullptr;
  bool first_sample = false;  // the pixel's sample 0, whose hit names the `object` pass
};

// Adds the camera ray's hit to state.first_hit, when set (a miss adds nothing).
void add_first_hit(const Tracer& tracer, const Hit& hit, const SurfacePoint& surface, SampleState& state);

glm::dvec3 direct_radiance(const Tracer& tracer, const Lights& lights, const Ray& ray, SampleState& state);
glm::dvec3 path_radiance(const Tracer& tracer, const Lights& lights, const Ray& ray, SampleState& state);

}  // namespace vkray::cpu
