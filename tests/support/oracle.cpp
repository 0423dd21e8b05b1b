#include "support/oracle.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vkray::test {
namespace {

double det3(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {  // determinant of the matrix with columns a, b, c
  return a.x * (b.y * c.z - b.z * c.y) - b.x * (a.y * c.z - a.z * c.y) + c.x * (a.y * b.z - a.z * b.y);
}

}  // namespace

Oracle::Oracle(const Scene& scene, uint32_t width, uint32_t height) : scene_(scene), width_(width), height_(height) {
  origin_ = glm::dvec3(scene.camera.position);
  forward_ = glm::normalize(glm::dvec3(scene.camera.forward));
  right_ = glm::normalize(glm::cross(forward_, glm::dvec3(scene.camera.up)));
  up_ = glm::cross(right_, forward_);
  focal_px_ = double(scene.camera.focal_length) * height;
  epsilon_ = double(scene.extent()) * 1e-5;
}

Oracle::Hit Oracle::closest(glm::dvec3 o, glm::dvec3 d, double t_min, double t_max) const {
  Hit best{t_max, -1};
  for (size_t i = 0; i < scene_.triangles.size(); ++i) {
    const auto& tri = scene_.triangles[i];
    const glm::dvec3 v0(tri.v[0]), e1 = glm::dvec3(tri.v[1]) - v0, e2 = glm::dvec3(tri.v[2]) - v0;
    // [-d, e1, e2] (t, u, v)^T = o - v0, by Cramer's rule.
    const glm::dvec3 b = o - v0;
    const double det = det3(-d, e1, e2);
    if (det == 0.0) continue;
    const double t = det3(b, e1, e2) / det, u = det3(-d, b, e2) / det, v = det3(-d, e1, b) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && t > t_min && t < best.t) best = {t, int(i)};
  }
  for (size_t i = 0; i < scene_.spheres.size(); ++i) {
    const auto& s = scene_.spheres[i];
    // |o + t d - c|^2 = r^2: a t^2 + b t + c = 0.
    const glm::dvec3 oc = o - glm::dvec3(s.center);
    const double a = glm::dot(d, d), b = 2 * glm::dot(d, oc), c = glm::dot(oc, oc) - double(s.radius) * s.radius;
    const double disc = b * b - 4 * a * c;
    if (disc < 0) continue;
    for (double t : {(-b - std::sqrt(disc)) / (2 * a), (-b + std::sqrt(disc)) / (2 * a)}) {
      if (t > t_min && t < best.t) {
        best = {t, int(scene_.triangles.size() + i)};
        break;
      }
    }
  }
  return best;
}

OracleSample Oracle::trace(double px, double py) const {
  OracleSample sample;
  sample.lit_by.assign(scene_.lights.size(), false);
  const double x = px - width_ / 2.0, y = height_ / 2.0 - py;
  const glm::dvec3 d = glm::normalize(x * right_ + y * up_ + focal_px_ * forward_);
  const Hit hit = closest(origin_, d, epsilon_, std::numeric_limits<double>::max());
  if (hit.primitive < 0) {
    sample.radiance = glm::dvec3(scene_.background);
    return sample;
  }
  sample.primitive = hit.primitive;
  const glm::dvec3 p = origin_ + hit.t * d;
  glm::dvec3 n;
  uint32_t material;
  if (size_t(hit.primitive) < scene_.triangles.size()) {
    const auto& tri = scene_.triangles[size_t(hit.primitive)];
    n = glm::normalize(glm::cross(glm::dvec3(tri.v[1]) - glm::dvec3(tri.v[0]), glm::dvec3(tri.v[2]) - glm::dvec3(tri.v[0])));
    material = tri.material;
  } else {
    const auto& s = scene_.spheres[size_t(hit.primitive) - scene_.triangles.size()];
    n = (p - glm::dvec3(s.center)) / double(s.radius);
    material = s.material;
  }
  if (glm::dot(n, d) > 0) n = -n;

  glm::dvec3 irradiance(scene_.ambient);
  const glm::dvec3 shadow_origin = p + epsilon_ * n;
  for (size_t l = 0; l < scene_.lights.size(); ++l) {
    const glm::dvec3 light(scene_.lights[l].position);
    const double r2 = glm::dot(light - p, light - p);
    const double cos_theta = glm::dot(n, (light - p) / std::sqrt(r2));
    if (!(cos_theta > 0)) continue;
    const double dist = glm::length(light - shadow_origin);
    if (closest(shadow_origin, (light - shadow_origin) / dist, epsilon_, dist - epsilon_).primitive >= 0) continue;
    sample.lit_by[l] = true;
    irradiance += glm::dvec3(scene_.lights[l].intensity) * cos_theta / (M_PI * r2);
  }
  sample.radiance = glm::dvec3(scene_.materials[material].albedo) * irradiance;
  return sample;
}

bool Oracle::stable(uint32_t i, uint32_t j) const {
  const double cx = i + 0.5, cy = j + 0.5, h = 0.02;
  const OracleSample centre = trace(cx, cy);
  for (auto [dx, dy] : {std::pair{h, 0.0}, {-h, 0.0}, {0.0, h}, {0.0, -h}})
    if (!(trace(cx + dx, cy + dy) == centre)) return false;
  return true;
}

}  // namespace vkray::test
