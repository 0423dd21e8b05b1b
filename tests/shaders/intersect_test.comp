// Runs the renderer's own intersection routines and triangle normals (shaders/intersect.glsl) on a list of test cases.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "intersect.glsl"
#include "intersect_case.h"

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Cases { IntersectCase cases[]; };
layout(std430, binding = 1) writeonly buffer Results { float t[]; };
layout(push_constant) uniform Count { uint count; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  IntersectCase c = cases[i];
  Ray ray = Ray(c.origin.xyz, c.dir.xyz);
  if (c.range.z == 0.0)
    t[i] = intersect_triangle(ray, ray_shear(ray.dir), c.a.xyz, c.b.xyz, c.c.xyz, c.range.x, c.range.y);
  else if (c.range.z == 1.0)
    t[i] = intersect_sphere(ray, c.a.xyz, c.a.w, c.range.x, c.range.y);
  else if (c.range.z == 2.0)  // the triangle's normal against the expected one, in dir: 1 when they agree
    t[i] = dot(triangle_normal(c.a.xyz, c.b.xyz, c.c.xyz), c.dir.xyz);
  else  // the barycentric b1 of the hit, from the test's edge functions
    t[i] = triangle_hit_barycentrics(ray, c.a.xyz, c.b.xyz, c.c.xyz).x;
}
