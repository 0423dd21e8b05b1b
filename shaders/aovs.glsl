// The first-hit passes (AOVs, image/aovs.h): what each camera ray hits first, summed over the pixel's
// samples in the AOV output, which a later dispatch of the tile continues as it does the radiance.
// Compiled in only when a render asks for them (FIRST_HIT_PASSES).
#ifndef VKRAY_AOVS_GLSL
#define VKRAY_AOVS_GLSL

#include "shared/first_hit_layout.h"
#include "primitives.glsl"
#include "ray.glsl"
#include "resources.glsl"

layout(std430, set = 0, binding = VKRAY_BINDING_AOVS) buffer AovOutput { FirstHitTexels first_hit_output[]; };

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
  FirstHitTexels t = first_hit_output[index];
  first_hits = FirstHitSums(first_hit_albedo(t), first_hit_count(t), first_hit_normal(t), first_hit_object(t),
                            first_hit_position(t), first_hit_depth(t));
}

void store_first_hits(uint index) {
  first_hit_output[index] = first_hit_texels(first_hits.albedo, first_hits.hits, first_hits.normal, first_hits.object,
                                             first_hits.position, first_hits.depth);
}

// Called by the integrators where the camera ray hit surface `s` at x, t along the (unit) ray.
void add_first_hit(Hit hit, vec3 x, Surface s) {
  first_hits.hits += 1u;
  first_hits.albedo += (s.properties & VKRAY_BSDF_CLEAR) != 0u ? vec3(1.0) : s.albedo;
  first_hits.normal += s.shading_normal;
  first_hits.position += x;
  first_hits.depth += hit.t;
  if (first_sample)  // an instance's primitives belong to the object that places it
    first_hits.object = SCENE_HAS_INSTANCES && hit.instance != NO_INSTANCE
                            ? int(instance_header(hit.instance).object)
                            : int(primitive_object(texelFetch(primitives, int(hit.prim) * VKRAY_TEXELS_PER_PRIMITIVE + 2)));
}

#endif
