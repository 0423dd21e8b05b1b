// Small scenes compiled into the shader: GLSL that tests every primitive of a packed scene, with
// the primitives' coordinates written as constants. On llvmpipe each BVH step of a small scene
// costs as much as testing dozens of triangles with constants (README, "Benchmark"), so below a
// size the tracer tests them all instead of walking the hierarchy.
#pragma once

#include <cstdint>
#include <string>

#include "gpu/scene_packing.h"

namespace vkray::gpu {

// How a scene is traced: by code compiled from it (every primitive tested, its coordinates constants
// in the shader) or by walking its BVH in the scene buffers.
enum class InlineScene {
  automatic,  // compiled in when the scene is small and the render traces enough camera rays to repay the compile
  always,     // compiled in whenever the scene is small (at most kMaxInlinePrimitives primitives)
  never,      // always the BVH
};

// Scenes of at most this many primitives can be compiled into the shader.
constexpr uint32_t kMaxInlinePrimitives = 32;

// The body of shaders/inline_scene.glsl's contract for `packed`: a function
//   void test_inline_primitives(Ray ray, RayShear shear, float t_min, inout Hit hit, inout uint hit_index)
// that calls test_inline_triangle / test_inline_sphere (shaders/scene.glsl) once per primitive, in
// the scene's order, each with its coordinates as literals (exact: 17 significant digits) and its
// place in the primitive buffer. Empty when the scene has no primitives.
std::string inline_scene_glsl(const PackedScene& packed);

}  // namespace vkray::gpu
