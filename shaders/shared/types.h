// The interface between the C++ host and trace.comp: binding numbers, specialization constants,
// workgroup size, and the uniform and push-constant structs, each written once for both languages
// (the scene buffers' texel layouts are in scene_layout.h, the first-hit passes' in
// first_hit_layout.h). The C++ side static_asserts every member's std140 offset right here. The
// binding table in host/gpu/pipeline.cpp gives each binding its descriptor type, and the shader's
// own declarations are checked against it when it is compiled.
#ifndef VKRAY_SHARED_TYPES_H
#define VKRAY_SHARED_TYPES_H

#include "glsl_cpp.h"

VKRAY_SHARED_BEGIN

// ---- Descriptor bindings (set 0) -------------------------------------------------------------
// Scene data is in uniform texel buffers, which llvmpipe reads about twice as fast as storage
// buffers (docs/design.md, "Scene buffers").
#define VKRAY_BINDING_FRAME 0       // uniform buffer: FrameUniforms
#define VKRAY_BINDING_PRIMITIVES 1  // uniform texel buffer, RGBA32F: PrimitiveTexels, in BVH leaf order
#define VKRAY_BINDING_NORMALS 2     // uniform texel buffer, RGBA32F: vertex normals of smooth triangles
#define VKRAY_BINDING_NODES 3       // uniform texel buffer, RGBA32UI: 4-wide BVH nodes
#define VKRAY_BINDING_MATERIALS 4   // uniform texel buffer, RGBA32F: materials
#define VKRAY_BINDING_LIGHTS 5      // uniform texel buffer, RGBA32F: point, spot and directional lights
#define VKRAY_BINDING_OUTPUT 6      // storage buffer: one vec4 per pixel (rgb radiance, a = ray count bits)
#define VKRAY_BINDING_EMITTERS 7    // uniform texel buffer, RGBA32F: the area lights' alias table
#define VKRAY_BINDING_AOVS 8        // storage buffer: FirstHitTexels per pixel (first_hit_layout.h)
#define VKRAY_BINDING_TEXCOORDS 9   // uniform texel buffer, RGBA32F: texture coordinates of textured triangles
#define VKRAY_BINDING_TEXTURES 10   // uniform texel buffer, RGBA16F: every texture's texels
#define VKRAY_BINDING_TANGENTS 11   // uniform texel buffer, RGBA32F: vertex tangents of normal-mapped triangles
#define VKRAY_BINDING_COLOURS 12    // uniform texel buffer, RGBA32F: vertex colours of coloured triangles
#define VKRAY_BINDING_INSTANCES 13  // uniform texel buffer, RGBA32F: the instances (scene_layout.h)
#define VKRAY_BINDING_ENVIRONMENT 14      // uniform texel buffer, RGBA32F: the environment map's texels (scene_layout.h)
#define VKRAY_BINDING_ENVIRONMENT_CDF 15  // uniform texel buffer, R32F: its sampling distribution (scene_layout.h)

// ---- Specialization constants ------------------------------------------------------------------
// One table: X(id, GLSL name, gpu::ShaderVariant member, default). resources.glsl declares each
// as `layout(constant_id = id) const bool NAME = default;` and the host builds the pipeline's
// specialization from the same rows (host/gpu/pipeline.cpp), so an id, a name and a member cannot
// be paired differently on the two sides.
// false when the scene has no spheres: the pipeline for it has no sphere test.
#define VKRAY_SPEC_SPHERES 0
// false for a render without shadow rays (every light counts as visible: camera rays alone, for
// `vkray bench`): the pipeline has no shadow-ray code, which would cost every lane, masked.
#define VKRAY_SPEC_SHADOWS 1
// true for the path integrator, false for the direct model (Scene::integrator).
#define VKRAY_SPEC_PATH 2
// false when no material emits: no area-light code.
#define VKRAY_SPEC_EMITTERS 3
// false when every material is purely Lambertian: no code for the other BSDFs.
#define VKRAY_SPEC_NON_DIFFUSE 4
// true when the render also returns the first-hit passes (AOVs): aovs.glsl's code is compiled in.
#define VKRAY_SPEC_AOVS 5
// false when no material has a texture: no texture coordinates and no texture code.
#define VKRAY_SPEC_TEXTURES 6
// false when every material is two-sided: camera rays meet back faces like any other ray.
#define VKRAY_SPEC_SINGLE_SIDED 7
// false when no material has a normal map: no tangents and no normal-map code.
#define VKRAY_SPEC_NORMAL_MAPS 8
// false when no material lets rays through (VKRAY_ALPHA_*): no alpha test, and no ray keys drawn.
#define VKRAY_SPEC_ALPHA 9
// false when every shading normal is the geometric one (no vertex normals, no normal maps): no code to
// bend a shading normal that faces away from the viewer (shade.glsl), which the geometric one never does.
#define VKRAY_SPEC_SHADING_NORMALS 10
// false when the scene has no point, spot or directional lights, and when its background is black or
// it is not path traced: no code for lighting by them (such a light's shadow ray; the path
// integrator's uniform background sample and its shadow ray).
// llvmpipe runs a block under a condition that no lane meets all the same, masked, and such a block
// holding a traversal loop costs a traversal step: on scenes/rough-spheres.json, lit by an area
// light alone under a black sky, the two blocks took a fifth of the trace time.
#define VKRAY_SPEC_POINT_LIGHTS 11
#define VKRAY_SPEC_BACKGROUND 12
// false when no triangle has vertex colours: no colours buffer read, and no code for them.
#define VKRAY_SPEC_VERTEX_COLOURS 13
// false when the scene places no mesh by instances: one level of BVH, and no code for a second.
#define VKRAY_SPEC_INSTANCES 14
// false when the scene has no environment map (Scene::environment): no code to look it up or sample it.
#define VKRAY_SPEC_ENVIRONMENT 15
// false for a render in which the path integrator finds the environment map by BSDF sampling alone,
// drawing no directions from it (RenderOptions::sample_environment: to measure what importance
// sampling buys).
#define VKRAY_SPEC_ENVIRONMENT_SAMPLED 16
// And one per material type, id VKRAY_SPEC_MATERIALS + its number (shared/materials.h): whether the
// scene has a material of that type (gpu::ShaderVariant::materials, a bit each); the BSDF code of
// the others is left out. Declared as SCENE_HAS_<name> (SCENE_HAS_roughconductor).
#define VKRAY_SPEC_MATERIALS 24
#define VKRAY_SPECIALIZATION_CONSTANTS(X)                     \
  X(VKRAY_SPEC_SPHERES, SCENE_HAS_SPHERES, spheres, true)     \
  X(VKRAY_SPEC_SHADOWS, SHADOW_RAYS, shadows, true)           \
  X(VKRAY_SPEC_PATH, PATH_TRACING, path, false)               \
  X(VKRAY_SPEC_EMITTERS, SCENE_HAS_EMITTERS, emitters, false) \
  X(VKRAY_SPEC_NON_DIFFUSE, SCENE_HAS_NON_DIFFUSE, non_diffuse, false) \
  X(VKRAY_SPEC_AOVS, FIRST_HIT_PASSES, aovs, false)           \
  X(VKRAY_SPEC_TEXTURES, SCENE_HAS_TEXTURES, textures, false) \
  X(VKRAY_SPEC_SINGLE_SIDED, SCENE_HAS_SINGLE_SIDED, single_sided, false) \
  X(VKRAY_SPEC_NORMAL_MAPS, SCENE_HAS_NORMAL_MAPS, normal_maps, false) \
  X(VKRAY_SPEC_ALPHA, SCENE_HAS_ALPHA, alpha, false) \
  X(VKRAY_SPEC_SHADING_NORMALS, SCENE_HAS_SHADING_NORMALS, shading_normals, true) \
  X(VKRAY_SPEC_POINT_LIGHTS, SCENE_HAS_POINT_LIGHTS, point_lights, true) \
  X(VKRAY_SPEC_BACKGROUND, SCENE_HAS_BACKGROUND, background, true) \
  X(VKRAY_SPEC_VERTEX_COLOURS, SCENE_HAS_VERTEX_COLOURS, vertex_colours, false) \
  X(VKRAY_SPEC_INSTANCES, SCENE_HAS_INSTANCES, instances, false) \
  X(VKRAY_SPEC_ENVIRONMENT, SCENE_HAS_ENVIRONMENT, environment, false) \
  X(VKRAY_SPEC_ENVIRONMENT_SAMPLED, ENVIRONMENT_SAMPLED, environment_sampled, true)

// ---- The visibility contract -----------------------------------------------------------------
// Two hits whose distances differ by less than this fraction are a tie (that is below float
// precision: a ray along the line where two walls meet, coplanar surfaces); the primitive that
// comes first in the scene wins, so the result does not depend on traversal order.
#define VKRAY_TIE 1e-5

// ---- The output's alpha --------------------------------------------------------------------------
// The bits of a uint: the rays traced for the pixel, and this bit when the driver cut the shader's
// loops short (llvmpipe's loop limiter; the host traces the tile again in smaller dispatches). A
// pixel's rays in one submission stay far below 2^31 (65536 samples of a few hundred rays each).
#define VKRAY_LOOPS_CUT_SHORT 0x80000000u

// ---- The direct model's mirrors and glass -----------------------------------------------------
// A camera ray passes through at most this many mirror or glass surfaces before it must meet a
// diffuse one (past it, the ray brings nothing): enough for a glass sphere seen in a mirror.
#define VKRAY_SPECULAR_BOUNCES 8u

// ---- Workgroup ---------------------------------------------------------------------------------
#define VKRAY_WORKGROUP_X 8
#define VKRAY_WORKGROUP_Y 8

// ---- Per-frame constants (std140 uniform block) ----------------------------------------------
// The camera follows the scene contract: d = normalize(x*right + y*up + focal_px*forward).
// Radiance here (background, ambient), in the materials' emission and in the lights' intensity is
// the scene's times a power of two that brings the brightest of them near 2^20 (gpu::LightingFrame):
// light transport is linear in them, so the shader's image is the scene's times that power exactly,
// which the host divides out, and no float the shader computes overflows or flushes to zero where
// the double-precision CPU reference's does not (docs/limits.md, "Floats on the GPU").
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
  uint seed_key;    // seed_key(seed) (shared/sampling.h)
  float aperture_radius;  // the thin lens; 0: the pinhole
  float focus_distance;
  int max_depth;          // the path integrator's; -1: no limit
  uint rr_depth;
  uint emitter_count;     // entries of the area lights' alias table
  uint environment_width;   // the environment map's size in texels (0: none)
  uint environment_height;
  uint unused0;     // std140 rounds the struct up to a multiple of 16 bytes; the buffer holds all of it
  // The rows of the rotation from world directions to the environment map's own (Mitsuba's envmap
  // to_world, inverted); w unused.
  vec4 environment_row0;
  vec4 environment_row1;
  vec4 environment_row2;
};
#ifdef __cplusplus
static_assert(offsetof(FrameUniforms, origin) == 0);
static_assert(offsetof(FrameUniforms, right) == 16);
static_assert(offsetof(FrameUniforms, up) == 32);
static_assert(offsetof(FrameUniforms, forward) == 48);
static_assert(offsetof(FrameUniforms, background) == 64);
static_assert(offsetof(FrameUniforms, ambient) == 80);
static_assert(offsetof(FrameUniforms, width) == 96);
static_assert(offsetof(FrameUniforms, height) == 100);
static_assert(offsetof(FrameUniforms, samples_per_pixel) == 104);
static_assert(offsetof(FrameUniforms, primitive_count) == 108);
static_assert(offsetof(FrameUniforms, light_count) == 112);
static_assert(offsetof(FrameUniforms, strata_x) == 116);
static_assert(offsetof(FrameUniforms, strata_y) == 120);
static_assert(offsetof(FrameUniforms, inv_strata_x) == 124);
static_assert(offsetof(FrameUniforms, inv_strata_y) == 128);
static_assert(offsetof(FrameUniforms, inv_samples_per_pixel) == 132);
static_assert(offsetof(FrameUniforms, epsilon) == 136);
static_assert(offsetof(FrameUniforms, seed_key) == 140);
static_assert(offsetof(FrameUniforms, aperture_radius) == 144);
static_assert(offsetof(FrameUniforms, focus_distance) == 148);
static_assert(offsetof(FrameUniforms, max_depth) == 152);
static_assert(offsetof(FrameUniforms, rr_depth) == 156);
static_assert(offsetof(FrameUniforms, emitter_count) == 160);
static_assert(offsetof(FrameUniforms, environment_width) == 164);
static_assert(offsetof(FrameUniforms, environment_height) == 168);
static_assert(offsetof(FrameUniforms, unused0) == 172);
static_assert(offsetof(FrameUniforms, environment_row0) == 176);
static_assert(offsetof(FrameUniforms, environment_row1) == 192);
static_assert(offsetof(FrameUniforms, environment_row2) == 208);
static_assert(sizeof(FrameUniforms) == 224);
#endif

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
  // The dispatch traces samples [sample_begin, sample_end) of each pixel, continuing the running sum
  // of samples weighed by 1 / samples_per_pixel that an earlier dispatch of the tile left in the
  // output (the same float additions in the same order as one loop over all samples): the mean, once
  // the dispatch that ends at samples_per_pixel is done.
  uint sample_begin;
  uint sample_end;
  // Where the tile's pixels start in the output, which holds a tile or two, not the image (any
  // image size fits a device's maxStorageBufferRange): row-major in the tile, width pixels a row.
  uint output_offset;
  // 2, from the host so that the compiler cannot unroll the loop that counts to it: the shader's
  // probe of llvmpipe's loop limiter (trace.comp).
  uint probe_iterations;
};
#ifdef __cplusplus
static_assert(offsetof(TileConstants, x0) == 0);
static_assert(offsetof(TileConstants, y0) == 4);
static_assert(offsetof(TileConstants, width) == 8);
static_assert(offsetof(TileConstants, height) == 12);
static_assert(offsetof(TileConstants, row_stride) == 16);
static_assert(offsetof(TileConstants, sample_begin) == 20);
static_assert(offsetof(TileConstants, sample_end) == 24);
static_assert(offsetof(TileConstants, output_offset) == 28);
static_assert(offsetof(TileConstants, probe_iterations) == 32);
static_assert(sizeof(TileConstants) == 36);
#endif

VKRAY_SHARED_END
#endif  // VKRAY_SHARED_TYPES_H
