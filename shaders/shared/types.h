// Everything that crosses between the C++ host and the GLSL shaders: binding numbers, workgroup size,
// the uniform and push-constant structs, and the texel layout of the scene buffers. Both languages
// include this file, so a binding number or a struct member is written exactly once. The C++ side
// static_asserts the std140 layout in host/packing/scene_packing.h.
#ifndef VKRAY_SHARED_TYPES_H
#define VKRAY_SHARED_TYPES_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace vkray::gpu {
using uint = std::uint32_t;
using glm::vec2;
using glm::vec3;
using glm::vec4;
#endif

// ---- Descriptor bindings (set 0) -------------------------------------------------------------
#define VKRAY_BINDING_FRAME 0       // uniform buffer: FrameUniforms
#define VKRAY_BINDING_PRIMITIVES 1  // uniform texel buffer, RGBA32F, VKRAY_TEXELS_PER_PRIMITIVE each, in BVH order
#define VKRAY_BINDING_NORMALS 2     // uniform texel buffer, RGBA32F, VKRAY_TEXELS_PER_PRIMITIVE each (smooth triangles)
#define VKRAY_BINDING_NODES 3       // uniform texel buffer, RGBA32UI, VKRAY_TEXELS_PER_NODE each
#define VKRAY_BINDING_MATERIALS 4   // uniform texel buffer, RGBA32F, one texel (albedo) each
#define VKRAY_BINDING_LIGHTS 5      // uniform texel buffer, RGBA32F, VKRAY_TEXELS_PER_LIGHT each
#define VKRAY_BINDING_OUTPUT 6      // storage buffer: one vec4 per pixel (rgb radiance, a = ray count bits)

// ---- Specialization constants ------------------------------------------------------------------
// false when the scene has no spheres: the pipeline for it has no sphere test (gpu::ShaderVariant).
#define VKRAY_SPEC_SPHERES 0
// false for a render without shadow rays (every light counts as visible: camera rays alone, for
// `vkray bench`): the pipeline has no shadow-ray code, which would cost every lane, masked.
#define VKRAY_SPEC_SHADOWS 1

// Texel buffers rather than storage buffers: with the triangles in a storage buffer instead, a
// 1024x1024 render on Mesa 22.3.6 lavapipe (2 cores) took 1.8-2.3x as long (README, "How the GPU
// path works").
//
// Primitive, in BVH leaf order: a triangle is (v0.xyz, flags), (v1.xyz, index), (v2.xyz, 0), vertices
// rather than edges, since the watertight test needs every triangle sharing a vertex to see bitwise
// the same coordinates; a sphere is (center.xyz, flags), (radius, 0, 0, index), (0). `index` is the
// primitive's place in the scene (bits of a uint), which decides ties (VKRAY_TIE).
// flags = material index | VKRAY_PRIM_SPHERE | VKRAY_PRIM_SMOOTH.
#define VKRAY_TEXELS_PER_PRIMITIVE 3
#define VKRAY_PRIM_SPHERE 0x80000000u
#define VKRAY_PRIM_SMOOTH 0x40000000u  // a triangle with vertex normals in the normals buffer
#define VKRAY_PRIM_MATERIAL_MASK 0x3fffffffu
// BVH node, 4-wide (host/packing/scene_packing.cpp collapses the binary BVH two levels at a time), in a
// RGBA32UI texel buffer, VKRAY_TEXELS_PER_NODE texels each:
//   0: (origin.xyz as float bits, e), e = ex | ey << 8 | ez << 16, biased float exponents
//   1: the four child links; 0 = no child (no node links to the root)
//   2: (lo.x, lo.y, lo.z, hi.x), 3: (hi.y, hi.z, 0, 0): byte c of each is child c's box corner in
//      steps of 2^(e - 127) from the origin, rounded outward, so a child's box always contains its
//      primitives: origin + q * 2^(e - 127) is exact up to the one rounding of the sum.
// A link is an inner node's index, or VKRAY_LEAF_BIT | first << VKRAY_LEAF_COUNT_BITS | count.
#define VKRAY_TEXELS_PER_NODE 4
#define VKRAY_NODE_WIDTH 4
#define VKRAY_LEAF_BIT 0x80000000u
#define VKRAY_LEAF_COUNT_BITS 4u
// A node pushes at most VKRAY_NODE_WIDTH - 1 children, and the binary BVH is at most 64 levels
// deep (host/bvh/bvh.h), so at most 32 wide ones.
#define VKRAY_TRAVERSAL_STACK 96
// Two hits whose distances differ by less than this fraction are a tie (that is below float
// precision: a ray along the line where two walls meet, coplanar surfaces); the primitive that
// comes first in the scene wins, so the result does not depend on traversal order.
#define VKRAY_TIE 1e-5
// Light: (position.xyz, 0), (intensity.rgb, 0).
#define VKRAY_TEXELS_PER_LIGHT 2

// ---- Workgroup ---------------------------------------------------------------------------------
#define VKRAY_WORKGROUP_X 8
#define VKRAY_WORKGROUP_Y 8

// ---- Per-frame constants (std140 uniform block) ----------------------------------------------
// The camera follows the scene contract: d = normalize(x*right + y*up + focal_px*forward).
struct FrameUniforms {
  vec4 origin;      // xyz: camera position; w: unused
  vec4 right;       // xyz: unit right vector r
  vec4 up;          // xyz: unit up vector u = r x f
  vec4 forward;     // xyz: unit view direction f; w: focal length in pixels F
  vec4 background;  // rgb: radiance of a ray that hits nothing
  vec4 ambient;     // rgb: ambient radiance A
  uint width;       // image size in pixels
  uint height;
  uint samples_per_pixel;
  uint primitive_count;  // 0: the scene has no geometry (no BVH to traverse)
  uint light_count;
  uint strata_x;    // sample pattern: strata_x * strata_y >= samples_per_pixel
  uint strata_y;
  float inv_strata_x;          // 1 / strata_x, computed once on the host
  float inv_strata_y;
  float inv_samples_per_pixel;
  float epsilon;    // self-intersection offset, scaled to the scene's extent
};

// ---- Push constants: the tile this dispatch covers ---------------------------------------------
struct TileConstants {
  uint x0;
  uint y0;
  uint width;
  uint height;
  // Workgroup row r of the dispatch renders row (r * row_stride) mod rows of the tile, a
  // permutation (row_stride is coprime with rows). llvmpipe hands each of its threads one
  // contiguous share of a dispatch's workgroups; scattered rows give every share a like mix of
  // cheap and costly pixels, so no thread finishes long before the others (gpu::row_stride).
  uint row_stride;
};

#ifdef __cplusplus
}  // namespace vkray::gpu
#endif
#endif  // VKRAY_SHARED_TYPES_H
