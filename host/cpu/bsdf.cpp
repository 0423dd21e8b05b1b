#include "cpu/bsdf.h"

#include <algorithm>
#include <cmath>

#include "cpu/warp.h"
#include "shared/sampling.h"

namespace vkray::cpu {

using glm::dvec2;
using glm::dvec3;

Bsdf bsdf_of(const Material& material, const dvec3& color, double metallic, double roughness, double transmission) {
  Bsdf b;
  b.type = material.type;
  b.properties = material.properties();
  b.color = color;
  b.ior = material.ior;
  b.alpha = dvec2(material.alpha);
  b.eta = dvec3(material.eta);
  b.k = dvec3(material.k);
  b.metallic = metallic;
  b.roughness = roughness;
  b.transmission = transmission;
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

dvec3 fresnel_conductor(double cos_i, const dvec3& eta, const dvec3& k) {
  // The s and p reflectances for a complex index eta + i k (pbrt-v3's FrConductor, Mitsuba's
  // fresnel_conductor), channel by channel.
  const double cos2 = cos_i * cos_i, sin2 = 1 - cos2;
  dvec3 r;
  for (int c = 0; c < 3; ++c) {
    const double eta2 = eta[c] * eta[c], k2 = k[c] * k[c];
    const double t0 = eta2 - k2 - sin2;
    const double a2_plus_b2 = std::sqrt(t0 * t0 + 4 * eta2 * k2);
    const double t1 = a2_plus_b2 + cos2;
    const double a = std::sqrt(std::max(0.0, (a2_plus_b2 + t0) / 2));
    const double t2 = 2 * cos_i * a;
    const double rs = (t1 - t2) / (t1 + t2);
    const double t3 = cos2 * a2_plus_b2 + sin2 * sin2;
    const double t4 = t2 * sin2;
    const double rp = rs * (t3 - t4) / (t3 + t4);
    r[c] = (rs + rp) / 2;
  }
  return r;
}

// ---- GGX microfacets (Trowbridge and Reitz 1975; Walter et al. 2007; Heitz 2014, 2018) -----------------

double ggx_density(const dvec3& m, const dvec2& alpha) {
  if (m.z <= 0) return 0;
  // D(m) = 1 / (pi ax ay (mx^2 / ax^2 + my^2 / ay^2 + mz^2)^2) for a unit m.
  const double e = (m.x / alpha.x) * (m.x / alpha.x) + (m.y / alpha.y) * (m.y / alpha.y) + m.z * m.z;
  return 1 / (kPi * alpha.x * alpha.y * e * e);
}

double smith_masking(const dvec3& v, const dvec3& m, const dvec2& alpha) {
  // A microfacet is seen only from its own side, and v only from above the surface.
  if (glm::dot(v, m) * v.z <= 0) return 0;
  const double xy = (alpha.x * v.x) * (alpha.x * v.x) + (alpha.y * v.y) * (alpha.y * v.y);
  if (xy == 0) return 1;  // straight down: nothing masks
  // G1 = 1 / (1 + Lambda), Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2.
  return 2 / (1 + std::sqrt(1 + xy / (v.z * v.z)));
}

dvec3 sample_visible_normal(const dvec3& v, const dvec2& alpha, double u1, double u2) {
  // Heitz 2018: stretch v to the hemisphere configuration, pick a point on the projected disk of the
  // visible half, lift it to the hemisphere, unstretch.
  const dvec3 vh = glm::normalize(dvec3(alpha.x * v.x, alpha.y * v.y, v.z));
  const double len2 = vh.x * vh.x + vh.y * vh.y;
  const dvec3 t1 = len2 > 0 ? dvec3(-vh.y, vh.x, 0) / std::sqrt(len2) : dvec3(1, 0, 0);
  const dvec3 t2 = glm::cross(vh, t1);
  const double r = std::sqrt(u1), phi = 2 * kPi * u2;
  const double p1 = r * std::cos(phi);
  const double s = (1 + vh.z) / 2;
  const double p2 = (1 - s) * std::sqrt(std::max(0.0, 1 - p1 * p1)) + s * (r * std::sin(phi));
  const dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1 - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(dvec3(alpha.x * nh.x, alpha.y * nh.y, std::max(0.0, nh.z)));
}

namespace {

// ---- roughconductor: F(wo . m) D(m) G1(wo) G1(wi) / (4 cos_o cos_i), as Mitsuba's with GGX ------------

dvec3 conductor_eval(const Bsdf& b, const dvec3& wo, const dvec3& wi) {
  if (wo.z <= 0 || wi.z <= 0) return dvec3(0.0);
  const dvec3 m = glm::normalize(wo + wi);
  const double dg = ggx_density(m, b.alpha) * smith_masking(wo, m, b.alpha) * smith_masking(wi, m, b.alpha);
  return b.color * fresnel_conductor(glm::dot(wo, m), b.eta, b.k) * (dg / (4 * wo.z));  // times cos_i
}

double conductor_pdf(const Bsdf& b, const dvec3& wo, const dvec3& wi) {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  const dvec3 m = glm::normalize(wo + wi);
  // The visible normals' density G1(wo) (wo . m) D / cos_o, times the reflection's 1 / (4 wi . m).
  return ggx_density(m, b.alpha) * smith_masking(wo, m, b.alpha) / (4 * wo.z);
}

// ---- roughdielectric: Walter et al. 2007, reflection and transmission through GGX microfacets ----------
// wo above the local frame (its side of the surface), eta = n_t / n_i across it. An index of 1 is no
// interface at all: light passes straight on, a delta (eval and pdf 0; sample says so).

// The half vector of a refraction from wo into wi, turned to wo's side; (0, 0, 0) when wo and wi do
// not lie on the two sides of it.
dvec3 refraction_half_vector(const dvec3& wo, const dvec3& wi, double eta) {
  dvec3 h = glm::normalize(wo + eta * wi);
  if (h.z < 0) h = -h;
  if (glm::dot(wo, h) <= 0 || glm::dot(wi, h) >= 0) return dvec3(0.0);
  return h;
}

dvec3 dielectric_eval(const Bsdf& b, const dvec3& wo, const dvec3& wi, double eta) {
  if (wo.z <= 0 || wi.z == 0 || eta == 1) return dvec3(0.0);
  double cos_t;
  if (wi.z > 0) {  // reflection: F D G / (4 cos_o cos_i), times cos_i
    const dvec3 h = glm::normalize(wo + wi);
    const double f = fresnel_dielectric(glm::dot(wo, h), eta, cos_t);
    return dvec3(f * ggx_density(h, b.alpha) * smith_masking(wo, h, b.alpha) * smith_masking(wi, h, b.alpha) / (4 * wo.z));
  }
  // Transmission: |wi.h| |wo.h| (1 - F) D G / (|cos_i| cos_o (wo.h + eta wi.h)^2), times |cos_i|: the
  // radiance form, which carries the 1 / eta^2 by which refraction compresses radiance.
  const dvec3 h = refraction_half_vector(wo, wi, eta);
  if (h == dvec3(0.0)) return dvec3(0.0);
  const double oh = glm::dot(wo, h), ih = glm::dot(wi, h), denominator = oh + eta * ih;
  const double f = fresnel_dielectric(oh, eta, cos_t);
  return dvec3((1 - f) * ggx_density(h, b.alpha) * smith_masking(wo, h, b.alpha) * smith_masking(wi, h, b.alpha) * oh *
               std::abs(ih) / (wo.z * denominator * denominator));
}

double dielectric_pdf(const Bsdf& b, const dvec3& wo, const dvec3& wi, double eta) {
  if (wo.z <= 0 || wi.z == 0 || eta == 1) return 0;
  double cos_t;
  if (wi.z > 0) {  // the visible normal's density, the choice of reflection (F), the Jacobian 1 / (4 wo.h)
    const dvec3 h = glm::normalize(wo + wi);
    const double f = fresnel_dielectric(glm::dot(wo, h), eta, cos_t);
    return ggx_density(h, b.alpha) * smith_masking(wo, h, b.alpha) * f / (4 * wo.z);
  }
  const dvec3 h = refraction_half_vector(wo, wi, eta);
  if (h == dvec3(0.0)) return 0;
  const double oh = glm::dot(wo, h), ih = glm::dot(wi, h), denominator = oh + eta * ih;
  const double f = fresnel_dielectric(oh, eta, cos_t);
  // ... and of refraction (1 - F), with the Jacobian eta^2 |wi.h| / (wo.h + eta wi.h)^2.
  return smith_masking(wo, h, b.alpha) * oh * ggx_density(h, b.alpha) / wo.z * (1 - f) * eta * eta * std::abs(ih) /
         (denominator * denominator);
}

// ---- metallic_roughness: glTF 2.0's material, as its specification's Appendix B writes it --------------
//   f = mix(dielectric, metal, metallic)
//   metal = specular * (base + (1 - base) (1 - |wo.h|)^5)
//   dielectric = mix(mix(base / pi, specular_btdf * base, transmission), specular, F),
//                F = f0 + (1 - f0) (1 - |wo.h|)^5, f0 = ((ior - 1) / (ior + 1))^2
//   specular = D(h) G1(wo) G1(wi) / (4 cos_o cos_i), GGX with alpha = roughness^2
// and KHR_materials_transmission's thin-walled specular_btdf: for wi below the surface, the same
// lobe at wi's mirror image above it (its half vector H_T = normalize(wo + wi - 2 (n.wi) n)), the
// light passing through unbent. Sampled by the visible normals (mirrored for transmission) or by
// cosine, the lobe picked by an estimate of each one's share.

double metallic_roughness_alpha(const Bsdf& b) { return std::max(b.roughness * b.roughness, double(VKRAY_MIN_GGX_ALPHA)); }

double dielectric_f0(const Bsdf& b) { return ((b.ior - 1) / (b.ior + 1)) * ((b.ior - 1) / (b.ior + 1)); }

// The probabilities of sampling the reflection lobe (x) and the transmission lobe (y) seen from wo;
// the diffuse lobe has the rest. The metal's weight and the dielectric's Schlick reflectance at wo,
// against the base's (1 - F) times the base colour's luminance, split by transmission.
glm::dvec2 lobe_shares(const Bsdf& b, const dvec3& wo) {
  const double f0 = dielectric_f0(b), f = f0 + (1 - f0) * std::pow(1 - std::min(1.0, wo.z), 5);
  const double luminance = 0.2126 * b.color.r + 0.7152 * b.color.g + 0.0722 * b.color.b;
  const double specular = b.metallic + (1 - b.metallic) * f, base = (1 - b.metallic) * (1 - f) * luminance;
  return specular + base > 0 ? glm::dvec2(specular, base * b.transmission) / (specular + base) : glm::dvec2(1.0, 0.0);
}

// A direction below the surface as its mirror image above it: where the thin-walled BTDF is evaluated.
dvec3 above(const dvec3& w) { return {w.x, w.y, std::abs(w.z)}; }

dvec3 metallic_roughness_eval(const Bsdf& b, const dvec3& wo, const dvec3& wi) {
  if (wo.z <= 0 || wi.z == 0 || (wi.z < 0 && !(b.transmission > 0))) return dvec3(0.0);
  const glm::dvec2 alpha(metallic_roughness_alpha(b));
  const dvec3 l = above(wi), h = glm::normalize(wo + l);
  const double schlick = std::pow(std::max(0.0, 1 - std::abs(glm::dot(wo, h))), 5);
  const double specular = ggx_density(h, alpha) * smith_masking(wo, h, alpha) * smith_masking(l, h, alpha) / (4 * wo.z * l.z);
  const double f0 = dielectric_f0(b), fresnel = f0 + (1 - f0) * schlick;
  if (wi.z < 0) return (1 - b.metallic) * (1 - fresnel) * b.transmission * specular * b.color * l.z;
  const dvec3 dielectric = (1 - fresnel) * (1 - b.transmission) * b.color / kPi + dvec3(fresnel * specular);
  const dvec3 metal = specular * (b.color + (1.0 - b.color) * schlick);
  return ((1 - b.metallic) * dielectric + b.metallic * metal) * l.z;
}

double metallic_roughness_pdf(const Bsdf& b, const dvec3& wo, const dvec3& wi) {
  if (wo.z <= 0 || wi.z == 0) return 0;
  const glm::dvec2 alpha(metallic_roughness_alpha(b));
  const dvec3 l = above(wi), h = glm::normalize(wo + l);
  const glm::dvec2 p = lobe_shares(b, wo);
  const double specular = ggx_density(h, alpha) * smith_masking(wo, h, alpha) / (4 * wo.z);
  if (wi.z < 0) return p.y * specular;
  return p.x * specular + std::max(0.0, 1 - p.x - p.y) * wi.z / kPi;  // (with transmission 1, 0 up to rounding)
}

}  // namespace

bool passes_straight_on(const Bsdf& b) { return b.type == MaterialType::roughdielectric && b.ior == 1; }

// ---- The three functions, by material ---------------------------------------------------------------------

dvec3 eval_bsdf(const Bsdf& b, const dvec3& wo, const dvec3& wi, const dvec3& n, bool front) {
  switch (b.type) {
    case MaterialType::diffuse:
      return b.color * (std::max(0.0, glm::dot(wi, n)) / kPi);
    case MaterialType::roughconductor:
      return conductor_eval(b, to_tangent_space(wo, n), to_tangent_space(wi, n));
    case MaterialType::roughdielectric:
      return dielectric_eval(b, to_tangent_space(wo, n), to_tangent_space(wi, n), front ? b.ior : 1 / b.ior);
    case MaterialType::metallic_roughness:
      return metallic_roughness_eval(b, to_tangent_space(wo, n), to_tangent_space(wi, n));
    case MaterialType::mirror:
    case MaterialType::glass:
      return dvec3(0.0);  // delta lobes: no direction but one
  }
  return dvec3(0.0);
}

double pdf_bsdf(const Bsdf& b, const dvec3& wo, const dvec3& wi, const dvec3& n, bool front) {
  switch (b.type) {
    case MaterialType::diffuse:
      return std::max(0.0, glm::dot(wi, n)) / kPi;
    case MaterialType::roughconductor:
      return conductor_pdf(b, to_tangent_space(wo, n), to_tangent_space(wi, n));
    case MaterialType::roughdielectric:
      return dielectric_pdf(b, to_tangent_space(wo, n), to_tangent_space(wi, n), front ? b.ior : 1 / b.ior);
    case MaterialType::metallic_roughness:
      return metallic_roughness_pdf(b, to_tangent_space(wo, n), to_tangent_space(wi, n));
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
    case MaterialType::roughconductor: {
      const double u1 = gpu::next_random(stream), u2 = gpu::next_random(stream);
      const dvec3 o = to_tangent_space(wo, n);
      b.dir = n;
      b.weight = dvec3(0.0);
      if (o.z <= 0) return b;  // seen from below its shading normal: no light
      const dvec3 m = sample_visible_normal(o, bsdf.alpha, u1, u2);
      const dvec3 i = 2 * glm::dot(o, m) * m - o;
      if (i.z <= 0) return b;  // reflected below the surface
      b.dir = glm::normalize(from_tangent_space(i, n));
      b.pdf = conductor_pdf(bsdf, o, i);
      // f cos / pdf = F G1(wi): D, G1(wo) and the cosines cancel.
      b.weight = bsdf.color * fresnel_conductor(glm::dot(o, m), bsdf.eta, bsdf.k) * smith_masking(i, m, bsdf.alpha);
      return b;
    }
    case MaterialType::roughdielectric: {
      const double u1 = gpu::next_random(stream), u2 = gpu::next_random(stream), u3 = gpu::next_random(stream);
      const double eta = front ? bsdf.ior : 1 / bsdf.ior;
      if (eta == 1) {  // no interface: straight on, whole
        b.delta = b.transmitted = true;
        b.dir = -wo;
        return b;
      }
      const dvec3 o = to_tangent_space(wo, n);
      b.dir = n;
      b.weight = dvec3(0.0);
      if (o.z <= 0) return b;
      const dvec3 m = sample_visible_normal(o, bsdf.alpha, u1, u2);
      const double cos_i = glm::dot(o, m);
      double cos_t;
      const double f = fresnel_dielectric(cos_i, eta, cos_t);
      if (u3 < f) {  // reflection, with probability F: f cos / pdf = G1(wi)
        const dvec3 i = 2 * cos_i * m - o;
        if (i.z <= 0) return b;
        b.dir = glm::normalize(from_tangent_space(i, n));
        b.pdf = dielectric_pdf(bsdf, o, i, eta);
        b.weight = dvec3(smith_masking(i, m, bsdf.alpha));
        return b;
      }
      // Refraction about m, with probability 1 - F: f cos / pdf = G1(wi) / eta^2.
      const dvec3 i = glm::normalize((cos_i / eta - cos_t) * m - o / eta);
      if (i.z >= 0) return b;
      b.dir = glm::normalize(from_tangent_space(i, n));
      b.pdf = dielectric_pdf(bsdf, o, i, eta);
      b.transmitted = true;
      b.eta = eta;
      b.weight = dvec3(smith_masking(i, m, bsdf.alpha) / (eta * eta));
      return b;
    }
    case MaterialType::metallic_roughness: {
      const double u_lobe = gpu::next_random(stream), u1 = gpu::next_random(stream), u2 = gpu::next_random(stream);
      const dvec3 o = to_tangent_space(wo, n);
      b.dir = n;
      b.weight = dvec3(0.0);
      if (o.z <= 0) return b;
      dvec3 i;
      const glm::dvec2 p = lobe_shares(bsdf, o);
      if (u_lobe < p.x + p.y) {  // a visible normal's reflection, mirrored through the surface to transmit
        const dvec3 m = sample_visible_normal(o, glm::dvec2(metallic_roughness_alpha(bsdf)), u1, u2);
        i = 2 * glm::dot(o, m) * m - o;
        if (i.z <= 0) return b;
        if (u_lobe >= p.x) i.z = -i.z;
      } else {
        i = cosine_hemisphere(u1, u2);
        if (i.z <= 0) return b;
      }
      // Any lobe may have given the direction: the weight is the whole BSDF over the mixed density.
      b.pdf = metallic_roughness_pdf(bsdf, o, i);
      if (!(b.pdf > 0)) return b;
      b.dir = glm::normalize(from_tangent_space(i, n));
      b.transmitted = i.z < 0;  // through a thin sheet: unbent, b.eta stays 1
      b.weight = metallic_roughness_eval(bsdf, o, i) / b.pdf;
      return b;
    }
  }
  return b;
}

}  // namespace vkray::cpu
