// The instances (shared/scene_layout.h, "Instances"): a ray moved into an instance's mesh space, and
// what is found there turned back to world space. Only a scene with instances reads them
// (SCENE_HAS_INSTANCES).
#ifndef VKRAY_INSTANCES_GLSL
#define VKRAY_INSTANCES_GLSL

#include "ray.glsl"
#include "resources.glsl"

const uint NO_INSTANCE = VKRAY_NO_INSTANCE;  // Hit::instance of the scene's own primitives

struct InstanceHeader {
  uint root;         // its BVH's root node
  uint first_index;  // added to its primitives' scene indices
  uint object;       // the object it places
  bool placed;       // false: the scene's own primitives, untransformed
};

InstanceHeader instance_header(uint entry) {
  vec4 h = texelFetch(instances, int(entry) * VKRAY_TEXELS_PER_INSTANCE + VKRAY_INSTANCE_HEADER);
  return InstanceHeader(floatBitsToUint(h.x), floatBitsToUint(h.y), floatBitsToUint(h.z), floatBitsToUint(h.w) != 0u);
}

// A ray moved by the affine transform with rows r0, r1, r2 (a world-to-mesh transform): its direction
// is not made unit again, so t is the same in both spaces.
Ray moved_ray(vec4 r0, vec4 r1, vec4 r2, Ray ray) {
  return Ray(vec3(dot(r0.xyz, ray.origin) + r0.w, dot(r1.xyz, ray.origin) + r1.w, dot(r2.xyz, ray.origin) + r2.w),
             vec3(dot(r0.xyz, ray.dir), dot(r1.xyz, ray.dir), dot(r2.xyz, ray.dir)));
}

// The ray in the entry's mesh space.
Ray ray_to_mesh(uint entry, Ray ray) {
  int base = int(entry) * VKRAY_TEXELS_PER_INSTANCE + VKRAY_INSTANCE_TO_MESH;
  return moved_ray(texelFetch(instances, base), texelFetch(instances, base + 1), texelFetch(instances, base + 2), ray);
}

// A mesh-space normal in world space, unit: by the inverse transpose, whose columns are the
// world-to-mesh transform's rows.
vec3 normal_to_world(uint entry, vec3 n) {
  int base = int(entry) * VKRAY_TEXELS_PER_INSTANCE + VKRAY_INSTANCE_TO_MESH;
  vec4 r0 = texelFetch(instances, base), r1 = texelFetch(instances, base + 1), r2 = texelFetch(instances, base + 2);
  return normalize(n.x * r0.xyz + n.y * r1.xyz + n.z * r2.xyz);
}

// A mesh-space point in world space.
vec3 point_to_world(uint entry, vec3 p) {
  int base = int(entry) * VKRAY_TEXELS_PER_INSTANCE + VKRAY_INSTANCE_TO_WORLD;
  vec4 r0 = texelFetch(instances, base), r1 = texelFetch(instances, base + 1), r2 = texelFetch(instances, base + 2);
  return vec3(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}

#endif
