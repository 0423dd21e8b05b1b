// Scene access and the two traversals every ray needs: closest hit (camera rays) and any hit
// (shadow rays). Brute force over all primitives for now; a BVH replaces these loops later.
#ifndef VKRAY_SCENE_GLSL
#define VKRAY_SCENE_GLSL

#include "shared/types.h"
#include "intersect.glsl"

layout(std140, set = 0, binding = VKRAY_BINDING_FRAME) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = VKRAY_BINDING_TRIANGLES) uniform samplerBuffer triangles;
layout(set = 0, binding = VKRAY_BINDING_SPHERES) uniform samplerBuffer spheres;
layout(set = 0, binding = VKRAY_BINDING_MATERIALS) uniform samplerBuffer materials;
layout(set = 0, binding = VKRAY_BINDING_LIGHTS) uniform samplerBuffer lights;

// ---- Closest hit ---------------------------------------------------------------------------------
Hit trace_closest(Ray ray, float t_min, float t_max) {
  RayShear shear = ray_shear(ray.dir);
  Hit hit = Hit(t_max, NO_HIT);
  for (uint i = 0u; i < frame.triangle_count; ++i) {
    int base = int(i) * VKRAY_TEXELS_PER_TRIANGLE;
    float t = intersect_triangle(ray, shear, texelFetch(triangles, base).xyz, texelFetch(triangles, base + 1).xyz,
                                 texelFetch(triangles, base + 2).xyz, t_min, hit.t);
    if (t > 0.0) hit = Hit(t, i);
  }
  for (uint i = 0u; i < frame.sphere_count; ++i) {
    vec4 sphere = texelFetch(spheres, int(i) * VKRAY_TEXELS_PER_SPHERE);
    float t = intersect_sphere(ray, sphere.xyz, sphere.w, t_min, hit.t);
    if (t > 0.0) hit = Hit(t, frame.triangle_count + i);
  }
  return hit;
}

// ---- Any hit: stops at the first occluder ----------------------------------------------------------
bool trace_any(Ray ray, float t_min, float t_max) {
  RayShear shear = ray_shear(ray.dir);
  for (uint i = 0u; i < frame.triangle_count; ++i) {
    int base = int(i) * VKRAY_TEXELS_PER_TRIANGLE;
    if (intersect_triangle(ray, shear, texelFetch(triangles, base).xyz, texelFetch(triangles, base + 1).xyz,
                           texelFetch(triangles, base + 2).xyz, t_min, t_max) > 0.0)
      return true;
  }
  for (uint i = 0u; i < frame.sphere_count; ++i) {
    vec4 sphere = texelFetch(spheres, int(i) * VKRAY_TEXELS_PER_SPHERE);
    if (intersect_sphere(ray, sphere.xyz, sphere.w, t_min, t_max) > 0.0) return true;
  }
  return false;
}

// ---- Surface data at a hit ---------------------------------------------------------------------------
// Geometric unit normal, not yet oriented toward the ray.
vec3 hit_normal(Hit hit, vec3 position) {
  if (hit.prim < frame.triangle_count) {
    int base = int(hit.prim) * VKRAY_TEXELS_PER_TRIANGLE;
    vec3 v0 = texelFetch(triangles, base).xyz;
    return normalize(cross(texelFetch(triangles, base + 1).xyz - v0, texelFetch(triangles, base + 2).xyz - v0));
  }
  vec4 sphere = texelFetch(spheres, int(hit.prim - frame.triangle_count) * VKRAY_TEXELS_PER_SPHERE);
  return (position - sphere.xyz) / sphere.w;
}

vec3 hit_albedo(Hit hit) {
  uint material;
  if (hit.prim < frame.triangle_count) {
    material = floatBitsToUint(texelFetch(triangles, int(hit.prim) * VKRAY_TEXELS_PER_TRIANGLE).w);
  } else {
    int base = int(hit.prim - frame.triangle_count) * VKRAY_TEXELS_PER_SPHERE;
    material = floatBitsToUint(texelFetch(spheres, base + 1).x);
  }
  return texelFetch(materials, int(material)).rgb;
}

#endif
