// The scene buffers' texel layouts, as code both sides run: the host packs with the functions here
// (host/packing/scene_packing.cpp) and the shader unpacks with them (shaders/traversal.glsl,
// primitives.glsl, shade.glsl), so a layout is written once and cannot drift between writer and reader.
#ifndef VKRAY_SHARED_SCENE_LAYOUT_H
#define VKRAY_SHARED_SCENE_LAYOUT_H

#include "glsl_cpp.h"
#include "materials.h"

VKRAY_SHARED_BEGIN

// ---- Primitives: VKRAY_TEXELS_PER_PRIMITIVE RGBA32F texels each, in BVH leaf order ---------------------
// A triangle is its vertices rather than its edges (every triangle sharing a vertex must see bitwise
// the same coordinates for the watertight test); a sphere is its centre and radius. Each carries its
// flags (material index | VKRAY_PRIM_SPHERE | VKRAY_PRIM_SMOOTH | VKRAY_PRIM_INWARD | VKRAY_PRIM_SINGLE_SIDED |
// VKRAY_PRIM_ALPHA | VKRAY_PRIM_COLOURED),
// its place in the scene, which decides ties (VKRAY_TIE), and the object it belongs to (the `object`
// pass), as the bits of floats.
#define VKRAY_TEXELS_PER_PRIMITIVE 3
#define VKRAY_PRIM_SPHERE 0x80000000u
#define VKRAY_PRIM_SMOOTH 0x40000000u  // a triangle with vertex normals in the normals buffer
#define VKRAY_PRIM_INWARD 0x20000000u  // a sphere whose normal points to its centre ("flip_normals")
// A triangle of a single-sided material (glTF's doubleSided false): camera rays pass its back face.
#define VKRAY_PRIM_SINGLE_SIDED 0x10000000u
// A primitive of a material that lets rays through where its alpha says so (shared/materials.h).
#define VKRAY_PRIM_ALPHA 0x08000000u
// A triangle with vertex colours in the colours buffer.
#define VKRAY_PRIM_COLOURED 0x04000000u
#define VKRAY_PRIM_MATERIAL_MASK 0x03ffffffu

struct PrimitiveTexels {
  vec4 a;  // triangle: (v0, flags);          sphere: (centre, flags)
  vec4 b;  // triangle: (v1, scene index);    sphere: (radius, 0, 0, scene index)
  vec4 c;  // triangle: (v2, object);         sphere: (0, 0, 0, object)
};

VKRAY_INLINE PrimitiveTexels triangle_texels(vec3 v0, vec3 v1, vec3 v2, uint flags, uint scene_index, uint object) {
  PrimitiveTexels t;
  t.a = vec4(v0, uintBitsToFloat(flags));
  t.b = vec4(v1, uintBitsToFloat(scene_index));
  t.c = vec4(v2, uintBitsToFloat(object));
  return t;
}

VKRAY_INLINE PrimitiveTexels sphere_texels(vec3 centre, float radius, uint flags, uint scene_index, uint object) {
  PrimitiveTexels t;
  t.a = vec4(centre, uintBitsToFloat(flags | VKRAY_PRIM_SPHERE));
  t.b = vec4(radius, 0.0f, 0.0f, uintBitsToFloat(scene_index));
  t.c = vec4(0.0f, 0.0f, 0.0f, uintBitsToFloat(object));
  return t;
}

VKRAY_INLINE uint primitive_flags(vec4 a) { return floatBitsToUint(a.w); }
VKRAY_INLINE uint primitive_scene_index(vec4 b) { return floatBitsToUint(b.w); }
VKRAY_INLINE uint primitive_object(vec4 c) { return floatBitsToUint(c.w); }
VKRAY_INLINE float sphere_radius(vec4 b) { return b.x; }

// Vertex normals of smooth triangles: a second buffer in the same slots as the primitives, one
// texel per vertex (xyz), present only when some triangle is smooth.

// Texture coordinates of textured triangles: a buffer in the same slots as the primitives,
// VKRAY_TEXELS_PER_TEXCOORDS texels each, the first set's (u0, v0, u1, v1), (u2, v2, and the second
// set's s0, t0), (s1, t1, s2, t2), present only when some material has a texture.
#define VKRAY_TEXELS_PER_TEXCOORDS 3

// Tangents of triangles whose material has a normal map: a buffer in the same slots as the
// primitives, one texel per vertex, (unit tangent, bitangent sign) as scene/scene.h's Triangle has
// them (sign 0: none), present only when some material has a normal map.
// Vertex colours of coloured triangles (VKRAY_PRIM_COLOURED): a buffer in the same slots as the
// primitives, one texel per vertex (rgba, each in [0, 1]), present only when some triangle is coloured.

// ---- Instances: VKRAY_TEXELS_PER_INSTANCE RGBA32F texels each ---------------------------------------
// Present when the scene places meshes by instances (vkray::Instance). The BVH is then two levels:
// the node buffer starts with a top BVH whose leaves name instance nodes (below: an instance, or the
// scene's own primitives, untransformed), and each names the root of its own BVH further on, over
// primitives in their own space. The entries here hold what shading needs. A ray enters an entry moved into that space by its to_mesh rows;
// its direction is not made unit again, so t is the same in both. A primitive's scene index there is
// its place in its mesh, and the entry's first scene index is added (vkray::PrimitiveNumbering).
// The traversal reads what it needs of an instance where it reads nodes: the top BVH's leaves name
// instance nodes, VKRAY_TEXELS_PER_NODE texels each in the node buffer (the three rows of the
// world-to-mesh transform as float bits, then (root node, first scene index, entry, 0)), entry being
// the instance's place in the instance buffer, or VKRAY_NO_INSTANCE for the scene's own primitives.
#define VKRAY_NO_INSTANCE 0xffffffffu

struct InstanceNode {
  vec4 row0, row1, row2;
  uint root;
  uint first_index;
  uint instance;
};

VKRAY_INLINE InstanceNode instance_node(uvec4 t0, uvec4 t1, uvec4 t2, uvec4 t3) {
  InstanceNode n;
  n.row0 = uintBitsToFloat(t0);
  n.row1 = uintBitsToFloat(t1);
  n.row2 = uintBitsToFloat(t2);
  n.root = t3.x;
  n.first_index = t3.y;
  n.instance = t3.z;
  return n;
}

#define VKRAY_TEXELS_PER_INSTANCE 7
#define VKRAY_INSTANCE_TO_MESH 0   // 3 texels: the rows of the world-to-mesh transform (affine, 3x4)
#define VKRAY_INSTANCE_TO_WORLD 3  // 3 texels: the rows of the mesh-to-world transform
// (root node, first scene index, object, placed) as uint bits; placed 0: the scene's own primitives,
// whose texels hold their scene index and object themselves and whose transforms are the identity.
#define VKRAY_INSTANCE_HEADER 6

VKRAY_INLINE vec4 instance_header_texel(uint root, uint first_index, uint object, uint placed) {
  return vec4(uintBitsToFloat(root), uintBitsToFloat(first_index), uintBitsToFloat(object), uintBitsToFloat(placed));
}

// ---- Materials: shared/materials.h ------------------------------------------------------------------

// The material a primitive's flags name.
VKRAY_INLINE uint primitive_material(uint flags) { return flags & VKRAY_PRIM_MATERIAL_MASK; }

// ---- Textures: RGBA16F texels in one buffer, each texture's rows one after another ---------------------
// A material names a texture by one texel, the bits of four uints: (its first texel in the buffer,
// width, height, mode); width 0: no texture. mode = wrap_s | wrap_t << 2 | filter << 4 |
// transformed << 5 | set << 6, with the values of vkray::TextureWrap and TextureFilter, which are glTF's
// sampler modes; transformed: the two texels after it map the texture coordinate (shared/materials.h);
// set: the primitive's texture coordinate set it reads (0 or 1, vkray::TextureRef::texcoord).
#define VKRAY_WRAP_REPEAT 0u
#define VKRAY_WRAP_CLAMP_TO_EDGE 1u
#define VKRAY_WRAP_MIRRORED_REPEAT 2u
#define VKRAY_FILTER_LINEAR 0u
#define VKRAY_FILTER_NEAREST 1u

struct TextureHeader {
  uint first;
  uint width;
  uint height;
  uint mode;
};

VKRAY_INLINE vec4 texture_texel(uint first, uint width, uint height, uint wrap_s, uint wrap_t, uint filter_mode, uint transformed,
                                 uint set) {
  return vec4(uintBitsToFloat(first), uintBitsToFloat(width), uintBitsToFloat(height),
              uintBitsToFloat(wrap_s | (wrap_t << 2u) | (filter_mode << 4u) | (transformed << 5u) | (set << 6u)));
}

VKRAY_INLINE TextureHeader texture_header(vec4 t) {
  TextureHeader h;
  h.first = floatBitsToUint(t.x);
  h.width = floatBitsToUint(t.y);
  h.height = floatBitsToUint(t.z);
  h.mode = floatBitsToUint(t.w);
  return h;
}

VKRAY_INLINE uint texture_wrap_s(uint mode) { return mode & 3u; }
VKRAY_INLINE uint texture_wrap_t(uint mode) { return (mode >> 2u) & 3u; }
VKRAY_INLINE uint texture_filter(uint mode) { return (mode >> 4u) & 1u; }
VKRAY_INLINE bool texture_transformed(uint mode) { return ((mode >> 5u) & 1u) != 0u; }
VKRAY_INLINE uint texture_texcoord_set(uint mode) { return (mode >> 6u) & 1u; }

// ---- Emissive primitives: the area lights, one RGBA32F texel each ------------------------------------
// An alias table (Walker 1977) over the primitives whose material emits, each weighted by its power
// (area times the luminance of its emission, where the scene places it): entry i is (probability,
// alias as uint bits, primitive as uint bits, instance + 1 as uint bits). The primitive is a slot in
// the primitive buffer on the GPU and the scene's numbering on the CPU; the instance is its entry in
// the instance buffer, 0 for none. One uniform u picks an entry with alias_pick; both renderers compute it in
// float, so they pick the same light for the same u.
#define VKRAY_TEXELS_PER_EMITTER 1

// The entry u lands in, and where in it: u * count splits into the entry (integer part) and the
// uniform that decides between it and its alias (fraction).
VKRAY_INLINE uint alias_entry(float u, uint count) { return min(uint(u * float(count)), count - 1u); }
VKRAY_INLINE bool alias_keeps_entry(float u, uint count, uint entry, float probability) {
  return u * float(count) - float(entry) < probability;
}

// The luminance (Rec. 709) that weighs an emission: the power of an area light is its area times it.
VKRAY_INLINE float emission_luminance(vec3 e) { return 0.2126f * e.x + 0.7152f * e.y + 0.0722f * e.z; }

// ---- Lights that are not surfaces (vkray::Light): VKRAY_TEXELS_PER_LIGHT RGBA32F texels each --------
#define VKRAY_TEXELS_PER_LIGHT 4
#define VKRAY_LIGHT_POSITION 0   // (position, kind as uint bits); a directional light's position is unused
#define VKRAY_LIGHT_INTENSITY 1  // (intensity, 0): W/sr, a spot's at its centre; a directional light's irradiance, W/m^2
#define VKRAY_LIGHT_DIRECTION 2  // (unit direction its light travels along: a spot's axis, 0); a point's is unused
#define VKRAY_LIGHT_CONE 3       // a spot's falloff: (cos cutoff, cos beam, cutoff, 1 / (cutoff - beam)) for
                                 // VKRAY_LIGHT_SPOT, (scale, offset, 0, 0) for VKRAY_LIGHT_GLTF_SPOT
// The kinds. VKRAY_LIGHT_SPOT falls off as Mitsuba's `spot`: 1 inside the beam width, linearly in
// the angle to 0 at the cutoff; VKRAY_LIGHT_GLTF_SPOT as KHR_lights_punctual's: the square of
// clamp(cos * scale + offset, 0, 1), from 1 inside the inner cone to 0 at the outer.
#define VKRAY_LIGHT_POINT 0u
#define VKRAY_LIGHT_SPOT 1u
#define VKRAY_LIGHT_GLTF_SPOT 2u
#define VKRAY_LIGHT_DIRECTIONAL 3u

// ---- The environment map (vkray::Environment): an equirectangular map of radiance -----------------------
// Oriented as Mitsuba's `envmap`: a direction d in the map's own frame (the frame's rows in
// FrameUniforms) lies at u = atan2(d.x, -d.z) / 2pi (wrapped into [0, 1)), v = acos(d.y) / pi, and
// texel (x, y), row y counted from the top, covers [x, x + 1) / width by [y, y + 1) / height of
// (u, v): its radiance is constant there. VKRAY_BINDING_ENVIRONMENT holds one texel per map texel,
// row by row: (radiance (times the frame's power of two), density), the density being that of
// picking a point of (u, v) in this texel, per unit area of (u, v), by sample_environment: the
// texel's luminance times sin(theta) at its row's centre, over their mean. VKRAY_BINDING_ENVIRONMENT_CDF
// holds the distribution that draws it, the cumulative sums of those weights: height rows of width
// numbers each, number x of row y the share of the row's weight in its texels 0 to x (the last one
// 1), then height numbers, number y the share of the whole map's in its rows 0 to y (the last one 1).
// A row without weight has equal shares, and is never picked.
#define VKRAY_ENVIRONMENT_ROW_CDF(width, y) ((y) * (width))
#define VKRAY_ENVIRONMENT_MARGINAL_CDF(width, height) ((width) * (height))

// ---- BVH links ---------------------------------------------------------------------------------------
// A child link is an inner node's index, or a leaf: VKRAY_LEAF_BIT | first << VKRAY_LEAF_COUNT_BITS |
// count, first the leaf's first primitive in leaf order, count 1 to 2^VKRAY_LEAF_COUNT_BITS - 1.
#define VKRAY_LEAF_BIT 0x80000000u
#define VKRAY_LEAF_COUNT_BITS 4u

VKRAY_INLINE uint leaf_link(uint first, uint count) { return VKRAY_LEAF_BIT | (first << VKRAY_LEAF_COUNT_BITS) | count; }
VKRAY_INLINE bool is_leaf(uint link) { return (link & VKRAY_LEAF_BIT) != 0u; }
VKRAY_INLINE uint leaf_first(uint link) { return (link & ~VKRAY_LEAF_BIT) >> VKRAY_LEAF_COUNT_BITS; }
VKRAY_INLINE uint leaf_count(uint link) { return link & ((1u << VKRAY_LEAF_COUNT_BITS) - 1u); }

// ---- BVH nodes: 4-wide, VKRAY_TEXELS_PER_NODE RGBA32UI texels each ---------------------------------
// The host collapses its binary BVH two levels at a time (host/packing/scene_packing.cpp):
//   VKRAY_NODE_HEADER:  (origin.xyz as float bits, e), e = ex | ey << 8 | ez << 16, biased float exponents
//   VKRAY_NODE_LINKS:   the four child links; 0 = no child (no node links to the root)
//   VKRAY_NODE_CORNERS and the texel after it: the corner words (NodeCorners)
// Byte c of a corner word is child c's box side along one axis in steps of 2^(e - 127) from the
// origin, rounded outward, so that a decoded box always contains the child's primitives.
#define VKRAY_TEXELS_PER_NODE 4
#define VKRAY_NODE_WIDTH 4
#define VKRAY_NODE_HEADER 0
#define VKRAY_NODE_LINKS 1
#define VKRAY_NODE_CORNERS 2
// A node pushes at most VKRAY_NODE_WIDTH - 1 children, and the binary BVH is at most 64 levels deep
// (host/bvh/bvh.h), so at most 32 wide ones.
#define VKRAY_TRAVERSAL_STACK 96

// The six corner words, low and high side per axis.
struct NodeCorners {
  uvec3 lo;
  uvec3 hi;
};
// How they sit in the node's last two texels: (lo.x, lo.y, lo.z, hi.x), (hi.y, hi.z, 0, 0).
struct NodeCornerTexels {
  uvec4 first;
  uvec4 second;
};

VKRAY_INLINE NodeCornerTexels node_corner_texels(NodeCorners c) {
  NodeCornerTexels t;
  t.first = uvec4(c.lo, c.hi.x);
  t.second = uvec4(c.hi.y, c.hi.z, 0u, 0u);
  return t;
}

VKRAY_INLINE NodeCorners node_corners(uvec4 first, uvec4 second) {
  NodeCorners c;
  c.lo = uvec3(first.x, first.y, first.z);
  c.hi = uvec3(first.w, second.x, second.y);
  return c;
}

// The step 2^(e - 127) per axis from the header's exponent word.
VKRAY_INLINE vec3 node_scale(uint exponents) {
  return uintBitsToFloat(((uvec3(exponents) >> uvec3(0u, 8u, 16u)) & 0xffu) << 23u);
}

// The four children's box sides along one axis, one child per component, from a corner word. The
// products are exact (q < 256 times a power of two), so fused or not, each sum is rounded once.
VKRAY_INLINE vec4 node_child_sides(float origin, float scale, uint corner_word) {
  return origin + vec4((uvec4(corner_word) >> uvec4(0u, 8u, 16u, 24u)) & 0xffu) * scale;
}

VKRAY_SHARED_END

#endif  // VKRAY_SHARED_SCENE_LAYOUT_H
