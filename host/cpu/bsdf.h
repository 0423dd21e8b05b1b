// The CPU reference's BSDFs: the same materials as the shader's (shaders/bsdf.glsl), written again
// in double, each with eval, pdf and sample, drawing the same numbers from the sample's stream.
//
// Every function takes wo, unit, back along the incoming ray; n, the unit shading normal turned to
// the side the ray came from (so conductors and diffuse surfaces reflect on both sides); and front,
// whether the ray met the side the geometric normal faces (a dielectric's outside). Glossy lobes
// are written in the frame tangent_frame builds about n (cpu/warp.h), whose first tangent is alpha_u's.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray::cpu {

// A material's BSDF at one point: its values, its textures applied.
struct Bsdf {
  MaterialType type = MaterialType::diffuse;
  uint32_t properties = 0;  // VKRAY_BSDF_* (shared/materials.h)
  glm::dvec3 color{0.0};    // albedo, reflectance or specular reflectance
  double ior = 1.5;
  glm::dvec2 alpha{0.1};
  glm::dvec3 eta{0.0}, k{1.0};
  double metallic = 1, roughness = 1, transmission = 0;

  bool has(uint32_t property) const { return (properties & property) != 0; }
};

// The BSDF of `material` where its colour, textures applied, is `color`, and (metallic_roughness)
// its metallic, roughness and transmission are `metallic`, `roughness` and `transmission`, their
// textures applied.
Bsdf bsdf_of(const Material& material, const glm::dvec3& color, double metallic, double roughness, double transmission);
// ... where nothing is textured.
inline Bsdf bsdf_of(const Material& material, const glm::dvec3& color) {
  return bsdf_of(material, color, material.metallic, material.roughness, material.transmission);
}

struct BsdfSample {
  glm::dvec3 dir;             // unit, away from the surface
  glm::dvec3 weight{1.0};     // f |cos| / pdf; 0 when the sample failed (the path ends)
  double pdf = 0;             // solid-angle density; 0 for a delta BSDF
  bool delta = false;
  bool transmitted = false;   // into the other side
  double eta = 1;             // n_t / n_i of a refraction; 1 otherwise
};

// f(wo, wi) |n . wi|: what light arriving from wi sends toward wo, per unit of its radiance and solid
// angle. 0 for delta BSDFs and for directions a lobe does not reach.
glm::dvec3 eval_bsdf(const Bsdf& bsdf, const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& n, bool front);
// The solid-angle density with which sample_bsdf picks wi; 0 for delta BSDFs.
double pdf_bsdf(const Bsdf& bsdf, const glm::dvec3& wo, const glm::dvec3& wi, const glm::dvec3& n, bool front);
// A direction drawn with density pdf_bsdf (or a delta lobe's), from `stream`.
BsdfSample sample_bsdf(const Bsdf& bsdf, const glm::dvec3& wo, const glm::dvec3& n, bool front, uint32_t& stream);

// Whether the surface is no interface at all (a rough dielectric of index 1, which sample_bsdf passes
// straight on): the direct model passes the ray on there, as at a delta BSDF.
bool passes_straight_on(const Bsdf& bsdf);

// Fresnel reflectance of a smooth dielectric: cos_i > 0 on the incident side, eta = n_t / n_i. Sets
// cos_t, the cosine on the other side (0 past the critical angle, where it returns 1).
double fresnel_dielectric(double cos_i, double eta, double& cos_t);
// Fresnel reflectance of a conductor of complex index eta + i k, unpolarized, for cos_i in [0, 1].
glm::dvec3 fresnel_conductor(double cos_i, const glm::dvec3& eta, const glm::dvec3& k);

// The GGX (Trowbridge-Reitz) microfacet distribution in the local frame (z: the normal).
double ggx_density(const glm::dvec3& m, const glm::dvec2& alpha);
// Smith's masking of direction v by microfacets of normal m.
double smith_masking(const glm::dvec3& v, const glm::dvec3& m, const glm::dvec2& alpha);
// A microfacet normal visible from v (v.z > 0), drawn with density G1(v, m) max(0, v.m) D(m) / v.z.
glm::dvec3 sample_visible_normal(const glm::dvec3& v, const glm::dvec2& alpha, double u1, double u2);

}  // namespace vkray::cpu
