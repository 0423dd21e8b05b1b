// The CPU reference's warps from uniform numbers to the shapes it samples, in double: the same maps
// as the shader's (shaders/warp.glsl), written again, so that the same numbers give the same points.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

namespace vkray::cpu {

constexpr double kPi = std::numbers::pi;

// Shirley and Chiu's concentric map of the unit square onto the unit disk.
inline glm::dvec2 concentric_disk(double u1, double u2) {
  const double a = 2 * u1 - 1, b = 2 * u2 - 1;
  if (a == 0 && b == 0) return {0, 0};
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4) * (b / a);
  } else {
    r = b;
    phi = kPi / 2 - (kPi / 4) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

// About +z, with density cos(theta) / pi.
inline glm::dvec3 cosine_hemisphere(double u1, double u2) {
  const glm::dvec2 d = concentric_disk(u1, u2);
  return {d.x, d.y, std::sqrt(std::max(0.0, 1 - d.x * d.x - d.y * d.y))};
}

// Uniform on the unit sphere: density 1 / (4 pi).
inline glm::dvec3 uniform_sphere(double u1, double u2) {
  const double z = 1 - 2 * u1;
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Barycentric weights (of v0, v1, v2) of a uniform point on a triangle.
inline glm::dvec3 uniform_triangle(double u1, double u2) {
  const double s = std::sqrt(u1);
  const double b0 = 1 - s, b1 = u2 * s;
  return {b0, b1, 1 - b0 - b1};
}

// An orthonormal basis about the unit vector n (Duff et al. 2017), the one the shader builds: its
// two tangents; (t, bt, n) is right-handed.
struct Frame {
  glm::dvec3 t, bt, n;
};
inline Frame frame_about(const glm::dvec3& n) {
  const double sign = n.z >= 0 ? 1.0 : -1.0;
  const double a = -1 / (sign + n.z);
  const double b = n.x * n.y * a;
  return {{1 + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}, n};
}

// `local` turned so that its +z is the unit vector n.
inline glm::dvec3 to_world(const glm::dvec3& local, const glm::dvec3& n) {
  const Frame f = frame_about(n);
  return local.x * f.t + local.y * f.bt + local.z * f.n;
}

// The frame the microfacet BSDFs are written in, whose first tangent is alpha_u's: the direction
// around the world's z axis, (-n.y, n.x, 0) normalized (a sphere's dp/du in Mitsuba), so that an
// anisotropic grain runs on without a seam; where n is the z axis itself, frame_about's.
inline Frame tangent_frame(const glm::dvec3& n) {
  const glm::dvec2 around(-n.y, n.x);
  const double len2 = glm::dot(around, around);
  if (len2 < 1e-12) return frame_about(n);
  const glm::dvec3 t(around / std::sqrt(len2), 0.0);
  return {t, glm::cross(n, t), n};
}

// The world direction v in the tangent frame about n: (t . v, bt . v, n . v).
inline glm::dvec3 to_tangent_space(const glm::dvec3& v, const glm::dvec3& n) {
  const Frame f = tangent_frame(n);
  return {glm::dot(v, f.t), glm::dot(v, f.bt), glm::dot(v, f.n)};
}

// A direction in the tangent frame about n, in the world.
inline glm::dvec3 from_tangent_space(const glm::dvec3& local, const glm::dvec3& n) {
  const Frame f = tangent_frame(n);
  return local.x * f.t + local.y * f.bt + local.z * f.n;
}

}  // namespace vkray::cpu
