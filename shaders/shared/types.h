// Everything that crosses between the C++ host and the GLSL shaders: binding numbers, workgroup size,
// the uniform and push-constant structs, and the texel layout of the scene buffers. Both languages
// include this file, so a binding number or a struct member is written exactly once. The C++ side
// static_asserts the std140 layout in host/gpu/scene_packing.h.
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
#define VKRAY_BINDING_FRAME 0      // uniform buffer: FrameUniforms
#define VKRAY_BINDING_TRIANGLES 1  // uniform texel buffer, RGBA32F, VKRAY_TEXELS_PER_TRIANGLE each
#define VKRAY_BINDING_SPHERES 2    // uniform texel buffer, RGBA32F, VKRAY_TEXELS_PER_SPHERE each
#define VKRAY_BINDING_MATERIALS 3  // uniform texel buffer, RGBA32F, one texel (albedo) each
#define VKRAY_BINDING_LIGHTS 4     // uniform texel buffer, RGBA32F, VKRAY_TEXELS_PER_LIGHT each
#define VKRAY_BINDING_OUTPUT 5     // storage buffer: one vec4 per pixel (rgb radiance, a = ray count bits)

// Texel buffers rather than storage buffers: with the triangles in a storage buffer instead, a
// 1024x1024 render on Mesa 22.3.6 lavapipe (2 cores) took 1.8-2.3x as long (README, "How the GPU
// path works").
// Triangle: (v0.xyz, material bits), (v1.xyz, 0), (v2.xyz, 0). Vertices, not edges: the watertight
// test needs every triangle sharing a vertex to see bitwise the same coordinates.
#define VKRAY_TEXELS_PER_TRIANGLE 3
// Sphere: (center.xyz, radius), (material bits, 0, 0, 0).
#define VKRAY_TEXELS_PER_SPHERE 2
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
  uint triangle_count;
  uint sphere_count;
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
};

#ifdef __cplusplus
}  // namespace vkray::gpu
#endif
#endif  // VKRAY_SHARED_TYPES_H
