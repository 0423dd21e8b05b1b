// Ray-primitive intersection, the lecture's formulations written for the GPU. Pure functions: no
// bindings, so the unit-test kernel (tests/shaders/intersect_test.comp) includes this file as is.
#ifndef VKRAY_INTERSECT_GLSL
#define VKRAY_INTERSECT_GLSL

#include "ray.glsl"

// Ray-triangle: the lecture's 3x3 system [-d, e1, e2] (t, u, v)^T = o - v0, solved in a ray-aligned
// frame where d = (0, 0, 1): there Cramer's rule reduces to three 2D edge functions U, V, W (the
// barycentrics times the determinant). This is the watertight test of Woop, Benthin and Wald
// (JCGT 2013): an edge shared by two triangles gives exactly negated edge functions in both, so a
// ray can never slip between them (the plain Cramer/Moller-Trumbore form leaves cracks along
// shared edges). Two-sided, edges inclusive. Returns t, or -1 for a miss.

// The per-ray part: the axis permutation k (kz = the dominant axis of d) and the shear S that
// maps d to (0, 0, 1).
struct RayShear {
  ivec3 k;
  vec3 s;
};

RayShear ray_shear(vec3 d) {
  vec3 ad = abs(d);
  int kz = (ad.x > ad.y) ? ((ad.x > ad.z) ? 0 : 2) : ((ad.y > ad.z) ? 1 : 2);
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  if (d[kz] < 0.0) {  // keep the winding (and so the sign of U, V, W) consistent
    int swap = kx;
    kx = ky;
    ky = swap;
  }
  return RayShear(ivec3(kx, ky, kz), vec3(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]));
}

// A point in the ray's frame: x, y its place in the plane across the ray (where the edge functions
// below are computed), z its depth, scaled so that the point at distance t along the ray has z = t.
// shear_point takes the point relative to the origin, and the shear as plain vectors.
vec3 shear_point(vec3 a, ivec3 k, vec3 s) { return vec3(a[k.x] - s.x * a[k.z], a[k.y] - s.y * a[k.z], s.z * a[k.z]); }

vec3 shear_vertex(Ray ray, RayShear sh, vec3 v) { return shear_point(v - ray.origin, sh.k, sh.s); }

// The test for a triangle whose vertices are already in the ray's frame (shear_vertex), without
// branches: on llvmpipe both sides of an if run anyway. Edge functions are `precise`: a fused
// multiply-add would break the exact antisymmetry that makes the test watertight. Outside: the
// edge functions differ in sign. det = 0: the ray lies in the triangle's plane, or the triangle is
// degenerate (its division by 0 is discarded with it).
float sheared_triangle(vec3 a, vec3 b, vec3 c, float t_min, float t_max) {
  precise float u = c.x * b.y - c.y * b.x;
  precise float v = a.x * c.y - a.y * c.x;
  precise float w = b.x * a.y - b.y * a.x;
  bool outside = (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0);
  float det = u + v + w;
  float t = (u * a.z + v * b.z + w * c.z) / det;
  return (!outside && det != 0.0 && t > t_min && t < t_max) ? t : -1.0;
}

float intersect_triangle(Ray ray, RayShear sh, vec3 v0, vec3 v1, vec3 v2, float t_min, float t_max) {
  return sheared_triangle(shear_vertex(ray, sh, v0), shear_vertex(ray, sh, v1), shear_vertex(ray, sh, v2), t_min, t_max);
}

// The barycentrics (b1, b2) of the point where a ray that hits the triangle meets it: the test's
// own edge functions for v1 and v2 over their sum. Each is a 2D cross product of coordinates, good
// to float precision of the coordinates whatever the triangle's shape, where barycentrics solved from
// the hit point lose digits as 1 / sin^2 of its smallest angle: on a sliver of a 2048-texel texture,
// a tenth of a texel.
vec2 triangle_hit_barycentrics(Ray ray, vec3 v0, vec3 v1, vec3 v2) {
  RayShear sh = ray_shear(ray.dir);
  vec3 a = shear_vertex(ray, sh, v0), b = shear_vertex(ray, sh, v1), c = shear_vertex(ray, sh, v2);
  precise float u = c.x * b.y - c.y * b.x;
  precise float v = a.x * c.y - a.y * c.x;
  precise float w = b.x * a.y - b.y * a.x;
  float det = u + v + w;
  return det != 0.0 ? vec2(v, w) / det : vec2(0.0);
}

// Ray-sphere: the quadratic |o + t d - c|^2 = r^2 with |d| = 1, i.e. t^2 - 2 b t + c = 0 with
// b = -dot(f, d), f = o - c. The discriminant is computed as r^2 - |f + b d|^2 rather than
// b^2 - c, which cancels catastrophically for small spheres far away ("Precision Improvements for
// Ray/Sphere Intersection", Ray Tracing Gems ch. 7). The nearest root in (t_min, t_max) counts, so a
// ray starting inside the sphere hits its far side. Returns t, or -1 for a miss.
float intersect_sphere(Ray ray, vec3 center, float radius, float t_min, float t_max) {
  vec3 f = ray.origin - center;
  float b = -dot(f, ray.dir);
  vec3 l = f + b * ray.dir;
  float discriminant = radius * radius - dot(l, l);
  if (discriminant < 0.0) return -1.0;
  // Compute the root of larger magnitude first, then the other from the product of the roots (= c),
  // so neither suffers cancellation.
  float q = b + (b >= 0.0 ? 1.0 : -1.0) * sqrt(discriminant);
  float c = dot(f, f) - radius * radius;
  float t0 = (q != 0.0) ? c / q : 0.0;
  float t1 = q;
  float near_t = min(t0, t1);
  float far_t = max(t0, t1);
  if (near_t > t_min && near_t < t_max) return near_t;
  if (far_t > t_min && far_t < t_max) return far_t;
  return -1.0;
}

// The direction of a triangle's normal, (v1 - v0) x (v2 - v0) times a positive number: the edges are
// brought to a size of about 1 first, which does not change the direction. For edges of 6e-10 the
// squared length of the plain cross product is near the smallest normal float, and a device that
// flushes subnormals to zero (NVIDIA's does) then normalizes by too short a length; for edges of
// 1e-12 it is 0 on every device (a NaN normal), and for 1e13 it overflows (a zero normal).
vec3 triangle_normal_direction(vec3 v0, vec3 v1, vec3 v2) {
  vec3 e1 = v1 - v0, e2 = v2 - v0;
  vec3 largest = max(abs(e1), abs(e2));
  float scale = 1.0 / max(largest.x, max(largest.y, largest.z));
  return cross(e1 * scale, e2 * scale);
}

// The unit normal of a triangle.
vec3 triangle_normal(vec3 v0, vec3 v1, vec3 v2) { return normalize(triangle_normal_direction(v0, v1, v2)); }

// ---- Ray-box ------------------------------------------------------------------------------------------
// 1 / d, with zero components replaced by a tiny number of the same sign, so that no slab test can
// compute 0 * inf = NaN.
vec3 safe_inverse(vec3 d) {
  vec3 magnitude = max(abs(d), vec3(1e-30));
  return vec3(d.x < 0.0 ? -1.0 : 1.0, d.y < 0.0 ? -1.0 : 1.0, d.z < 0.0 ? -1.0 : 1.0) / magnitude;
}

#endif
