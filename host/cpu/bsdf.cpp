#include "cpu/bsdf.h"

#include <algorithm>
#include <cmath>

#include "cpu/warp.h"
#include "shared/sampling.h"

namespace vkray::cpu {

using glm::dvec3;

Bsdf bsdf_of(const Material& material, const dvec3& color) {
  Bsdf b;
  b.type = material.type;
  b.properties = material.properties();
  b.color = color;
  b.ior = material.ior;
  return b;
}

// ---- Fresnel --------------------------------------------------------------------------------------------

double fresnel_dielectric(double cos_i, double eta, double& cos_t) {
  // Snell: sin_t = sin_i / eta.
  const double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) {  // total internal reflection
    cos_t = 0;
    return 1;
  }
  cos_t = std::sqrt(1 - sin2_t);
  const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return (rs * rs + rp * rp) / 2;
}

// ---- The three functions, by material ---------------------------------------------------------------------

dvec3 eval_bsdf(const Bsdf& b, const dvec3&, const dvec3& wi, const dvec3& n, bool) {
  switch (b.type) {
    case MaterialType::diffuse:
      return b.color * (std::max(0.0, glm::dot(wi, n)) / kPi);
    case MaterialType::mirror:
    case MaterialType::glass:
      return dvec3(0.0);  // delta lobes: no direction but one
  }
  return dvec3(0.0);
}

double pdf_bsdf(const Bsdf& b, const dvec3&, const dvec3& wi, const dvec3& n, bool) {
  switch (b.type) {
    case MaterialType::diffuse:
      return std::max(0.0, glm::dot(wi, n)) / kPi;
    case MaterialType::mirror:
    case MaterialType::glass:
      return 0;
  }
  return 0;
}

BsdfSample sample_bsdf(const Bsdf& bsdf, const dvec3& wo, const dvec3& n, bool front, uint32_t& stream) {
  BsdfSample b;
  switch (bsdf.type) {
    case MaterialType::diffuse: {
      const double u1 = gpu::next_random(stream), u2 = gpu::next_random(stream);
      const dvec3 local = cosine_hemisphere(u1, u2);
      b.dir = glm::normalize(to_world(local, n));  // as the shader does (bsdf.glsl says why)
      b.pdf = local.z / kPi;
      b.weight = bsdf.color;  // (albedo / pi) cos / (cos / pi)
      return b;
    }
    case MaterialType::mirror:
      b.delta = true;
      b.dir = glm::normalize(2 * glm::dot(wo, n) * n - wo);
      b.weight = bsdf.color;
      return b;
    case MaterialType::glass: {
      b.delta = true;
      const double cos_i = glm::dot(wo, n);
      const double eta = front ? bsdf.ior : 1 / bsdf.ior;
      double cos_t;
      const double f = fresnel_dielectric(cos_i, eta, cos_t);
      if (gpu::next_random(stream) < f) {
        b.dir = glm::normalize(2 * cos_i * n - wo);
        return b;
      }
      // Refraction: the tangential part scales by 1 / eta, the normal part is cos_t.
      b.dir = glm::normalize((cos_i / eta - cos_t) * n - wo / eta);
      b.transmitted = true;
      b.eta = eta;
      b.weight = dvec3(1 / (eta * eta));  // radiance is compressed into the narrower cone
      return b;
    }
  }
  return b;
}

}  // namespace vkray::cpu
