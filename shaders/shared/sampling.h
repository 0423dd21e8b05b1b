// The sample pattern, shared verbatim by the GPU shader and the CPU side (which compiles it as C++
// against GLM), so both renderers trace exactly the same rays.
//
// Pattern: with spp = 1 the single sample is the pixel centre (0.5, 0.5). Otherwise the pixel is cut
// into strata_x * strata_y cells (strata_x = ceil(sqrt(spp)), strata_y = ceil(spp / strata_x), chosen
// on the host); sample k sits in cell (k mod strata_x, k div strata_x), jittered inside it by two
// 24-bit uniforms from a PCG hash of (pixel index, seed, k). The path integrator jitters its single
// sample too (a sample at the centre would sharpen the image). Every operation below is an integer op or a
// single correctly rounded float add/multiply, so the CPU and any conforming GPU agree bit for bit.
#ifndef VKRAY_SHARED_SAMPLING_H
#define VKRAY_SHARED_SAMPLING_H

#include "glsl_cpp.h"

VKRAY_SHARED_BEGIN

// PCG-RXS-M-XS 32-bit hash (Jarzynski & Olano, "Hash Functions for GPU Rendering", JCGT 2020).
VKRAY_INLINE uint pcg_hash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// The top 24 bits as a float in [0, 1): exact, since 24 bits fit a float mantissa.
VKRAY_INLINE float hash_to_unit(uint h) { return float(h >> 8u) * (1.0f / 16777216.0f); }

// What a seed adds to every pixel's hash: 0 for seed 0, the streams vkray always had.
VKRAY_INLINE uint seed_key(uint seed) { return seed == 0u ? 0u : pcg_hash(seed ^ 0x6a09e667u); }

// The hash that jitters sample k of pixel `pixel_index` (= y * width + x).
VKRAY_INLINE uint sample_hash(uint pixel_index, uint seed_key, uint k) { return pcg_hash((pcg_hash(pixel_index) ^ seed_key) + k); }

// Offset of sample k inside its stratum's cell, in [0, 1)^2, always jittered.
VKRAY_INLINE vec2 jittered_offset(uint pixel_index, uint seed_key, uint k, uint strata_x, float inv_strata_x,
                                  float inv_strata_y) {
  uint h1 = sample_hash(pixel_index, seed_key, k);
  uint h2 = pcg_hash(h1);
  uint cell_x = k % strata_x;
  uint cell_y = k / strata_x;
  return vec2((float(cell_x) + hash_to_unit(h1)) * inv_strata_x,
              (float(cell_y) + hash_to_unit(h2)) * inv_strata_y);
}

// Offset of sample k inside pixel `pixel_index`, in [0, 1)^2: the pixel centre when it is the only sample.
VKRAY_INLINE vec2 sample_offset(uint pixel_index, uint seed_key, uint k, uint spp, uint strata_x, float inv_strata_x,
                                float inv_strata_y) {
  if (spp == 1u) return vec2(0.5f, 0.5f);
  return jittered_offset(pixel_index, seed_key, k, strata_x, inv_strata_x, inv_strata_y);
}

// ---- The random numbers of a sample past its pixel offset --------------------------------------------
// Every other decision a sample makes (a point on the lens, on a light, a direction, Russian
// roulette) draws the next number of the sample's own stream: PCG32 (O'Neill 2014, the RXS-M-XS
// output) started from the sample's hash. Both renderers draw in the same order, so that they
// trace the same paths and parity can be tight (docs/design.md, "Path tracing: how two renderers
// trace the same paths").
VKRAY_INLINE uint sample_stream(uint pixel_index, uint seed_key, uint k) {
  return pcg_hash(sample_hash(pixel_index, seed_key, k) ^ 0x9e3779b9u);
}

// The next 32-bit word of a stream.
VKRAY_INLINE uint next_word(VKRAY_INOUT(uint) state) {
  state = state * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// The next uniform in [0, 1) of a stream (24 bits: exact in a float).
VKRAY_INLINE float next_random(VKRAY_INOUT(uint) state) { return hash_to_unit(next_word(state)); }

// ---- Stochastic opacity ------------------------------------------------------------------------------
// A ray in a scene with see-through materials (shared/materials.h, alpha modes) carries a key, one
// word of its sample's stream drawn just before it is traced; a primitive of a blended material that
// the ray reaches is then solid for it when alpha_random(key, the primitive's place in the scene,
// which side) is below its opacity. One number per ray and surface: a sphere is two, the side a ray
// enters by and the side it leaves by (far_side); two surfaces on one ray, or one surface on two
// rays, decide independently, and a ray meets a surface with probability exactly its opacity.
VKRAY_INLINE float alpha_random(uint key, uint scene_index, bool far_side) {
  return hash_to_unit(pcg_hash(key ^ pcg_hash(((scene_index << 1u) | (far_side ? 1u : 0u)) ^ 0x3c6ef372u)));
}

VKRAY_SHARED_END
#endif  // VKRAY_SHARED_SAMPLING_H
