// Small scenes compiled into the shader: GLSL that tests every primitive of a packed scene, with
// the primitives' coordinates written as constants. On llvmpipe one BVH step of a small scene costs
// as much as testing about a dozen triangles with constants (docs/design.md, "Small scenes compiled
// into the shader"), so below a size the tracer can test them all instead of walking the hierarchy.
#pragma once

#include <cstdint>
#include <string>

#include "packing/scene_packing.h"

namespace vkray::gpu {

// Scenes of at most this many primitives can be compiled into the shader. Its code and compile time
// grow with each primitive, its rays' cost too, where a BVH walk's grows with the logarithm: on
// lavapipe a path-traced scene's rays cost the same both ways near 100 primitives (docs/design.md).
constexpr uint32_t kMaxInlinePrimitives = 64;

// The text served as shaders/inline_scene.glsl for `packed` (the contract is in that file): it
// defines VKRAY_INLINE_SCENE and test_inline_primitives(), which shears each distinct vertex once
// (shear_point) and tests every primitive once, in the scene's order, with sheared_triangle or
// intersect_sphere, coordinates as literals (exact: 17 significant digits), keeping the hit's place
// in the primitive buffer. Empty when the scene has no primitives.
std::string inline_scene_glsl(const PackedGeometry& packed);

}  // namespace vkray::gpu
