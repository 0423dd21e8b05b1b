#include "cpu/bsdf.h"

#include <cmath>

#include "cpu/warp.h"
#include "shared/sampling.h"

namespace vkray::cpu {

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

BsdfSample sample_bsdf(const Material& material, const glm::dvec3& albedo, const glm::dvec3& wo, const glm::dvec3& n, bool front, uint32_t& stream) {
  BsdfSample b;
  switch (material.type) {
    case MaterialType::diffuse: {
      const double u1 = gpu::next_random(stream), u2 = gpu::next_random(stream);
      const glm::dvec3 local = cosine_hemisphere(u1, u2);
      b.dir = glm::normalize(to_world(local, n));  // as the shader does (bsdf.glsl says why)
      b.pdf = local.z / kPi;
      b.weight = albedo;  // (albedo / pi) cos / (cos / pi)
      return b;
    }
    case MaterialType::mirror:
      b.delta = true;
      b.dir = glm::normalize(2 * glm::dot(wo, n) * n - wo);
      b.weight = albedo;
      return b;
    case MaterialType::glass: {
      b.delta = true;
      const double cos_i = glm::dot(wo, n);
      const double eta = front ? double(material.ior) : 1 / double(material.ior);
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
      b.weight = glm::dvec3(1 / (eta * eta));  // radiance is compressed into the narrower cone
      return b;
    }
  }
  return b;
}

}  // namespace vkray::cpu
