// The first-hit passes (AOVs, image/aovs.h): what each camera ray hits first, summed over the pixel's
// samples in the AOV output, which a later dispatch of the tile continues as it does the radiance.
// Compiled in only when a render asks for them (FIRST_HIT_PASSES).
#ifndef VKRAY_AOVS_GLSL
#define VKRAY_AOVS_GLSL

#include "primitives.glsl"
#include "ray.glsl"
#include "resources.glsl"

layout(std430, set = 0, binding = VKRAY_BINDING_AOVS) buffer AovOutput { vec4 aov_texels[]; };

struct FirstHitSums {
  vec3 albedo;
  uint hits;
  vec3 normal;
  int object;  // of the pixel's sample 0; -1: it hit nothing
  vec3 position;
  float depth;
};

FirstHitSums first_hits;
bool first_sample;  // the sample under way is the pixel's sample 0 (set by trace.comp)

// The sums an earlier dispatch of the tile left at `index`, or none.
void load_first_hits(uint index, bool continuing) {
  first_hits = FirstHitSums(vec3(0.0), 0u, vec3(0.0), -1, vec3(0.0), 0.0);
  if (!continuing) return;
  int base = int(index) * VKRAY_TEXELS_PER_AOV_PIXEL;
  vec4 a = aov_texels[base], b = aov_texels[base + 1], c = aov_texels[base + 2];
  first_hits = FirstHitSums(a.rgb, floatBitsToUint(a.w), b.xyz, floatBitsToInt(b.w), c.xyz, c.w);
}

void store_first_hits(uint index) {
  int base = int(index) * VKRAY_TEXELS_PER_AOV_PIXEL;
  aov_texels[base] = vec4(first_hits.albedo, uintBitsToFloat(first_hits.hits));
  aov_texels[base + 1] = vec4(first_hits.normal, intBitsToFloat(first_hits.object));
  aov_texels[base + 2] = vec4(first_hits.position, first_hits.depth);
}

// Called by the integrators where the camera ray hit surface `s` at x, t along the (unit) ray.
void add_first_hit(Hit hit, vec3 x, Surface s) {
  first_hits.hits += 1u;
  first_hits.albedo += s.material_type == VKRAY_MATERIAL_GLASS ? vec3(1.0) : s.albedo;
  first_hits.normal += s.shading_normal;
  first_hits.position += x;
  first_hits.depth += hit.t;
  if (first_sample)
    first_hits.object = int(primitive_object(texelFetch(primitives, int(hit.prim) * VKRAY_TEXELS_PER_PRIMITIVE + 2)));
}

#endif
