// The first-hit passes' output texels, as code both sides run: the shader packs a pixel's running
// sums with first_hit_texels and, continuing a tile, reads them back with the accessors below
// (shaders/aovs.glsl); the host reads the finished sums with the same accessors (host/gpu/renderer.cpp),
// so the layout is written once.
#ifndef VKRAY_SHARED_FIRST_HIT_LAYOUT_H
#define VKRAY_SHARED_FIRST_HIT_LAYOUT_H

#include "glsl_cpp.h"

VKRAY_SHARED_BEGIN

// One pixel's sums over its samples that hit something, in the AOV output (VKRAY_BINDING_AOVS): an
// array of these, in the same places as the radiance output's pixels. The hit count and the object
// travel as the bits of floats; the host divides by the hits (image/aovs.h).
struct FirstHitTexels {
  vec4 a;  // (albedo sum, hits)
  vec4 b;  // (shading normal sum, object of sample 0; -1: it hit nothing)
  vec4 c;  // (position sum, depth sum)
};
#ifdef __cplusplus
static_assert(offsetof(FirstHitTexels, a) == 0);
static_assert(offsetof(FirstHitTexels, b) == 16);
static_assert(offsetof(FirstHitTexels, c) == 32);
static_assert(sizeof(FirstHitTexels) == 48);  // std430's stride of the shader's array
#endif

VKRAY_INLINE FirstHitTexels first_hit_texels(vec3 albedo, uint hits, vec3 normal, int object, vec3 position, float depth) {
  FirstHitTexels t;
  t.a = vec4(albedo, uintBitsToFloat(hits));
  t.b = vec4(normal, intBitsToFloat(object));
  t.c = vec4(position, depth);
  return t;
}

VKRAY_INLINE vec3 first_hit_albedo(FirstHitTexels t) { return vec3(t.a); }
VKRAY_INLINE uint first_hit_count(FirstHitTexels t) { return floatBitsToUint(t.a.w); }
VKRAY_INLINE vec3 first_hit_normal(FirstHitTexels t) { return vec3(t.b); }
VKRAY_INLINE int first_hit_object(FirstHitTexels t) { return floatBitsToInt(t.b.w); }
VKRAY_INLINE vec3 first_hit_position(FirstHitTexels t) { return vec3(t.c); }
VKRAY_INLINE float first_hit_depth(FirstHitTexels t) { return t.c.w; }

VKRAY_SHARED_END
#endif  // VKRAY_SHARED_FIRST_HIT_LAYOUT_H
