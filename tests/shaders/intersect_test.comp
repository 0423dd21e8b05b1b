// Runs the renderer's own intersection routines (shaders/intersect.glsl) on a list of test cases.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "intersect.glsl"

layout(local_size_x = 64) in;

struct Case {
  vec4 origin;  // xyz
  vec4 dir;     // xyz, unit length
  vec4 a;       // triangle: v0; sphere: center (xyz) and radius (w)
  vec4 b;       // triangle: v1
  vec4 c;       // triangle: v2
  vec4 range;   // t_min, t_max, kind (0 triangle, 1 sphere)
};

layout(std430, binding = 0) readonly buffer Cases { Case cases[]; };
layout(std430, binding = 1) writeonly buffer Results { float t[]; };
layout(push_constant) uniform Count { uint count; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  Case c = cases[i];
  Ray ray = Ray(c.origin.xyz, c.dir.xyz);
  t[i] = (c.range.z == 0.0) ? intersect_triangle(ray, ray_shear(ray.dir), c.a.xyz, c.b.xyz, c.c.xyz, c.range.x, c.range.y)
                            : intersect_sphere(ray, c.a.xyz, c.a.w, c.range.x, c.range.y);
}
