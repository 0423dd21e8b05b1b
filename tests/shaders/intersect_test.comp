// Runs the renderer's own intersection routines (shaders/intersect.glsl) on a list of test cases.
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
  t[i] = (c.range.z == 0.0) ? intersect_triangle(ray, ray_shear(ray.dir), c.a.xyz, c.b.xyz, c.c.xyz, c.range.x, c.range.y)
                            : intersect_sphere(ray, c.a.xyz, c.a.w, c.range.x, c.range.y);
}
