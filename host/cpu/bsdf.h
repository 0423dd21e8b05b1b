// The CPU reference's BSDFs, sampled: the same three materials as the shader's (shaders/bsdf.glsl),
// drawing the same numbers from the sample's stream.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray::cpu {

struct BsdfSample {
  glm::dvec3 dir;             // unit, away from the surface
  glm::dvec3 weight{1.0};     // f cos / pdf
  double pdf = 0;             // solid-angle density; 0 for a delta BSDF
  bool delta = false;
  bool transmitted = false;   // into the other side
  double eta = 1;             // n_t / n_i of a refraction; 1 otherwise
};

// Fresnel reflectance of a smooth dielectric: cos_i > 0 on the incident side, eta = n_t / n_i. Sets
// cos_t, the cosine on the other side (0 past the critical angle, where it returns 1).
double fresnel_dielectric(double cos_i, double eta, double& cos_t);

// wo: unit, back along the incoming ray; n: the shading normal on wo's side; front: the ray met the
// side the geometric normal faces (glass: from outside); albedo: the material's, its texture applied
// (SurfacePoint::albedo). Draws from `stream`.
BsdfSample sample_bsdf(const Material& material, const glm::dvec3& albedo, const glm::dvec3& wo, const glm::dvec3& n, bool front, uint32_t& stream);

}  // namespace vkray::cpu
