// The first-hit passes (image/aovs.h) as the CPU reference records them, the same rule as
// shaders/aovs.glsl written apart from it.
#include "cpu/integrators.h"

namespace vkray::cpu {

void add_first_hit(const Tracer& tracer, const Hit& hit, const SurfacePoint& surface, SampleState& state) {
  FirstHitSums* sums = state.first_hit;
  if (!sums) return;
  const Scene& scene = tracer.scene();
  const Material& material = scene.materials[surface.material];
  ++sums->hits;
  sums->albedo += material.has(VKRAY_BSDF_CLEAR) ? dvec3(1.0) : surface.albedo;
  sums->normal += surface.shading_normal;
  sums->position += surface.position;
  sums->depth += hit.t;  // along a unit direction
  if (state.first_sample) {
    sums->object = int32_t(tracer.numbering().object(uint64_t(hit.primitive)));
  }
}

}  // namespace vkray::cpu
