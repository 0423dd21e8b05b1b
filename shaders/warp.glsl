// Warps from uniform random numbers to the shapes the tracer samples: the lens disk, the cosine-
// weighted hemisphere, the sphere, a point on a triangle. The CPU reference writes the same maps
// in its own code (host/cpu/sampling.h): the same numbers give the same points on both.
#ifndef VKRAY_WARP_GLSL
#define VKRAY_WARP_GLSL

const float PI = 3.14159265358979;

// Shirley and Chiu's concentric map of [0,1)^2 onto the unit disk (it keeps strata compact).
vec2 concentric_disk(vec2 u) {
  vec2 p = 2.0 * u - 1.0;
  if (p.x == 0.0 && p.y == 0.0) return vec2(0.0);
  bool x_major = abs(p.x) > abs(p.y);
  float r = x_major ? p.x : p.y;
  float phi = x_major ? (PI / 4.0) * (p.y / p.x) : (PI / 2.0) - (PI / 4.0) * (p.x / p.y);
  return r * vec2(cos(phi), sin(phi));
}

// A direction about +z with density cos(theta) / pi (Malley's method: the disk lifted to the hemisphere).
vec3 cosine_hemisphere(vec2 u) {
  vec2 d = concentric_disk(u);
  return vec3(d, sqrt(max(0.0, 1.0 - dot(d, d))));
}

// A direction on the unit sphere, uniformly: density 1 / (4 pi).
vec3 uniform_sphere(vec2 u) {
  float z = 1.0 - 2.0 * u.x;
  float r = sqrt(max(0.0, 1.0 - z * z));
  float phi = 2.0 * PI * u.y;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// Barycentric weights of a uniform point on a triangle: the point is b.x v0 + b.y v1 + b.z v2.
vec3 uniform_triangle(vec2 u) {
  float s = sqrt(u.x);
  float b0 = 1.0 - s;
  float b1 = u.y * s;
  return vec3(b0, b1, 1.0 - b0 - b1);
}

// The two tangents of an orthonormal basis about the unit vector n (Duff et al. 2017, branchless);
// (t, bt, n) is right-handed.
void frame_about(vec3 n, out vec3 t, out vec3 bt) {
  float sign = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (sign + n.z);
  float b = n.x * n.y * a;
  t = vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  bt = vec3(b, sign + n.y * n.y * a, -n.y);
}

// A local direction (x, y, z) turned so that +z is the unit vector n.
vec3 to_world(vec3 local, vec3 n) {
  vec3 t, bt;
  frame_about(n, t, bt);
  return local.x * t + local.y * bt + local.z * n;
}

// The frame the microfacet BSDFs are written in, whose first tangent is alpha_u's: the direction
// around the world's z axis, (-n.y, n.x, 0) normalized (a sphere's dp/du in Mitsuba), so that an
// anisotropic grain runs on without a seam; where n is the z axis itself, frame_about's.
void tangent_frame(vec3 n, out vec3 t, out vec3 bt) {
  vec2 around = vec2(-n.y, n.x);
  float len2 = dot(around, around);
  if (len2 < 1e-12) {
    frame_about(n, t, bt);
    return;
  }
  t = vec3(around * inversesqrt(len2), 0.0);
  bt = cross(n, t);
}

// The world direction v in the tangent frame about n: (t . v, bt . v, n . v).
vec3 to_tangent_space(vec3 v, vec3 n) {
  vec3 t, bt;
  tangent_frame(n, t, bt);
  return vec3(dot(v, t), dot(v, bt), dot(v, n));
}

// A direction in the tangent frame about n, in the world.
vec3 from_tangent_space(vec3 local, vec3 n) {
  vec3 t, bt;
  tangent_frame(n, t, bt);
  return local.x * t + local.y * bt + local.z * n;
}

#endif
