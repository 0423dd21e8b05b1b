// The materials' BSDFs (shared/materials.h names the types and their properties), each with eval,
// pdf and sample:
//   diffuse         Lambertian, albedo / pi, both sides; sampled by cosine (two numbers)
//   mirror          perfect specular reflection times the reflectance, both sides (no numbers)
//   glass           a smooth dielectric, ior inside and 1 outside (the geometric normal points out):
//                   Fresnel reflection or refraction, picked with probability F (one number)
//   roughconductor  GGX microfacets with Smith's masking, both sides, as Mitsuba's: the conductor's
//                   Fresnel term times the specular reflectance; visible normals sampled (two numbers)
//   roughdielectric GGX reflection and refraction (Walter et al. 2007), ior inside and 1 outside; a
//                   visible normal, then reflection with probability F or refraction (three numbers);
//                   an ior of 1 is no interface: light passes straight on
//   metallic_roughness  glTF 2.0's, as its specification's Appendix B writes it: a mix by `metallic` of
//                   a conductor with Schlick's Fresnel from the base colour and a dielectric (ior) over
//                   Lambert, or over KHR_materials_transmission's thin-walled BTDF by `transmission`
//                   (the specular lobe mirrored through the surface, times the base colour); GGX with
//                   alpha = roughness^2; a lobe, then a direction (three numbers)
// Every function takes wo, unit, back along the incoming ray; n, the shading normal turned to the
// ray's side; front, whether the ray met the side the geometric normal faces. Glossy lobes live in
// the frame tangent_frame(n) builds (warp.glsl), whose first tangent is alpha_u's. The CPU reference implements
// the same (host/cpu/bsdf.h).
#ifndef VKRAY_BSDF_GLSL
#define VKRAY_BSDF_GLSL

#include "primitives.glsl"
#include "shared/sampling.h"
#include "warp.glsl"

struct BsdfSample {
  vec3 dir;         // unit, away from the surface
  vec3 weight;      // f |cos| / pdf: what the path's throughput is multiplied by; 0: the sample failed
  float pdf;        // solid-angle density (0 for a delta BSDF)
  bool delta;       // mirror or glass
  bool transmitted; // the direction passes to the other side of the surface
  float eta;        // the relative index crossed (n_t / n_i); 1 unless transmitted
};

// ---- Fresnel -----------------------------------------------------------------------------------------

// The unpolarized Fresnel reflectance of a smooth dielectric for a cosine cos_i > 0 on the incident
// side and eta = n_t / n_i; 1 past the critical angle. cos_t returns the cosine on the other side.
float fresnel_dielectric(float cos_i, float eta, out float cos_t) {
  float sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) {
    cos_t = 0.0;
    return 1.0;
  }
  cos_t = sqrt(1.0 - sin2_t);
  float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// The unpolarized Fresnel reflectance of a conductor of complex index eta + i k, per channel, for
// cos_i in [0, 1] (the s and p terms in the form of pbrt-v3's FrConductor).
vec3 fresnel_conductor(float cos_i, vec3 eta, vec3 k) {
  float cos2 = cos_i * cos_i, sin2 = 1.0 - cos2;
  vec3 eta2 = eta * eta, k2 = k * k;
  vec3 t0 = eta2 - k2 - sin2;
  vec3 a2_plus_b2 = sqrt(t0 * t0 + 4.0 * eta2 * k2);
  vec3 t1 = a2_plus_b2 + cos2;
  vec3 a = sqrt(max(vec3(0.0), 0.5 * (a2_plus_b2 + t0)));
  vec3 t2 = 2.0 * cos_i * a;
  vec3 rs = (t1 - t2) / (t1 + t2);
  vec3 t3 = cos2 * a2_plus_b2 + sin2 * sin2;
  vec3 t4 = t2 * sin2;
  vec3 rp = rs * (t3 - t4) / (t3 + t4);
  return 0.5 * (rs + rp);
}

// ---- GGX microfacets ---------------------------------------------------------------------------------

// The Trowbridge-Reitz density of unit microfacet normals m in the local frame (z: the normal).
float ggx_density(vec3 m, vec2 alpha) {
  if (m.z <= 0.0) return 0.0;
  vec2 slope = m.xy / alpha;
  float e = dot(slope, slope) + m.z * m.z;
  return 1.0 / (PI * alpha.x * alpha.y * e * e);
}

// Smith's masking of v by microfacets of normal m: 1 / (1 + Lambda(v)).
float smith_masking(vec3 v, vec3 m, vec2 alpha) {
  if (dot(v, m) * v.z <= 0.0) return 0.0;  // a facet is seen only from its side, v only from above
  vec2 av = alpha * v.xy;
  float xy = dot(av, av);
  if (xy == 0.0) return 1.0;
  return 2.0 / (1.0 + sqrt(1.0 + xy / (v.z * v.z)));
}

// A microfacet normal visible from v (v.z > 0), with density G1(v, m) max(0, v . m) D(m) / v.z (Heitz
// 2018: stretch to the hemisphere configuration, a point on the visible half's projected disk, lifted).
vec3 sample_visible_normal(vec3 v, vec2 alpha, vec2 u) {
  vec3 vh = normalize(vec3(alpha * v.xy, v.z));
  float len2 = dot(vh.xy, vh.xy);
  vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x), phi = 2.0 * PI * u.y;
  float p1 = r * cos(phi);
  float s = 0.5 * (1.0 + vh.z);
  float p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * (r * sin(phi));
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(alpha * nh.xy, max(0.0, nh.z)));
}

// ---- roughconductor: F(wo . m) D(m) G1(wo) G1(wi) / (4 cos_o cos_i), in the local frame -------------------

vec3 conductor_eval(Surface s, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
  vec3 m = normalize(wo + wi);
  float dg = ggx_density(m, s.alpha) * smith_masking(wo, m, s.alpha) * smith_masking(wi, m, s.alpha);
  return s.albedo * fresnel_conductor(dot(wo, m), s.eta, s.k) * (dg / (4.0 * wo.z));  // times cos_i
}

float conductor_pdf(Surface s, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
  vec3 m = normalize(wo + wi);
  // The visible normals' density G1(wo) (wo . m) D / cos_o, times the reflection's 1 / (4 wi . m).
  return ggx_density(m, s.alpha) * smith_masking(wo, m, s.alpha) / (4.0 * wo.z);
}

// ---- roughdielectric, in the local frame, wo above it; eta = n_t / n_i across the surface ----------------

// The half vector of a refraction from wo into wi, turned to wo's side; 0 when wo and wi do not lie
// on its two sides.
vec3 refraction_half_vector(vec3 wo, vec3 wi, float eta) {
  vec3 h = normalize(wo + eta * wi);
  if (h.z < 0.0) h = -h;
  if (dot(wo, h) <= 0.0 || dot(wi, h) >= 0.0) return vec3(0.0);
  return h;
}

vec3 dielectric_eval(Surface s, vec3 wo, vec3 wi, float eta) {
  if (wo.z <= 0.0 || wi.z == 0.0 || eta == 1.0) return vec3(0.0);
  float cos_t;
  if (wi.z > 0.0) {  // reflection: F D G / (4 cos_o cos_i), times cos_i
    vec3 h = normalize(wo + wi);
    float f = fresnel_dielectric(dot(wo, h), eta, cos_t);
    return vec3(f * ggx_density(h, s.alpha) * smith_masking(wo, h, s.alpha) * smith_masking(wi, h, s.alpha) / (4.0 * wo.z));
  }
  // Transmission, in the radiance form: |wi.h| wo.h (1 - F) D G / (cos_o (wo.h + eta wi.h)^2).
  vec3 h = refraction_half_vector(wo, wi, eta);
  if (h == vec3(0.0)) return vec3(0.0);
  float oh = dot(wo, h), ih = dot(wi, h), denominator = oh + eta * ih;
  float f = fresnel_dielectric(oh, eta, cos_t);
  return vec3((1.0 - f) * ggx_density(h, s.alpha) * smith_masking(wo, h, s.alpha) * smith_masking(wi, h, s.alpha) * oh * abs(ih) /
              (wo.z * denominator * denominator));
}

float dielectric_pdf(Surface s, vec3 wo, vec3 wi, float eta) {
  if (wo.z <= 0.0 || wi.z == 0.0 || eta == 1.0) return 0.0;
  float cos_t;
  if (wi.z > 0.0) {  // the visible normal, the choice of reflection (F), the Jacobian 1 / (4 wo.h)
    vec3 h = normalize(wo + wi);
    float f = fresnel_dielectric(dot(wo, h), eta, cos_t);
    return ggx_density(h, s.alpha) * smith_masking(wo, h, s.alpha) * f / (4.0 * wo.z);
  }
  vec3 h = refraction_half_vector(wo, wi, eta);
  if (h == vec3(0.0)) return 0.0;
  float oh = dot(wo, h), ih = dot(wi, h), denominator = oh + eta * ih;
  float f = fresnel_dielectric(oh, eta, cos_t);
  // ... and of refraction (1 - F), with the Jacobian eta^2 |wi.h| / (wo.h + eta wi.h)^2.
  return smith_masking(wo, h, s.alpha) * oh * ggx_density(h, s.alpha) / wo.z * (1.0 - f) * eta * eta * abs(ih) /
         (denominator * denominator);
}

// ---- metallic_roughness, in the local frame, wo above it --------------------------------------------------

float metallic_roughness_alpha(Surface s) { return max(s.roughness * s.roughness, VKRAY_MIN_GGX_ALPHA); }

float dielectric_f0(Surface s) { return ((s.ior - 1.0) / (s.ior + 1.0)) * ((s.ior - 1.0) / (s.ior + 1.0)); }

// The probabilities of sampling the reflection lobe (x) and the transmission lobe (y) seen from wo;
// the diffuse lobe has the rest. The metal's weight and the dielectric's Schlick reflectance at wo,
// against the base's (1 - F) times the base colour's luminance, split by transmission.
vec2 lobe_shares(Surface s, vec3 wo) {
  float f0 = dielectric_f0(s), f = f0 + (1.0 - f0) * pow(1.0 - min(1.0, wo.z), 5.0);
  float specular = s.metallic + (1.0 - s.metallic) * f, base = (1.0 - s.metallic) * (1.0 - f) * emission_luminance(s.albedo);
  return specular + base > 0.0 ? vec2(specular, base * s.transmission) / (specular + base) : vec2(1.0, 0.0);
}

// The thin-walled BTDF takes a direction wi below the surface at its mirror image above it, l: the
// half vector is KHR_materials_transmission's H_T = normalize(wo + wi - 2 (n.wi) n).
vec3 metallic_roughness_eval(Surface s, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z == 0.0 || (wi.z < 0.0 && !(s.transmission > 0.0))) return vec3(0.0);
  vec2 alpha = vec2(metallic_roughness_alpha(s));
  vec3 l = vec3(wi.xy, abs(wi.z)), h = normalize(wo + l);
  float schlick = pow(max(0.0, 1.0 - abs(dot(wo, h))), 5.0);  // (GLSL leaves pow of a negative undefined)
  float specular = ggx_density(h, alpha) * smith_masking(wo, h, alpha) * smith_masking(l, h, alpha) / (4.0 * wo.z * l.z);
  float f0 = dielectric_f0(s), fresnel = f0 + (1.0 - f0) * schlick;
  if (wi.z < 0.0) return (1.0 - s.metallic) * (1.0 - fresnel) * s.transmission * specular * s.albedo * l.z;
  vec3 dielectric = (1.0 - fresnel) * (1.0 - s.transmission) * s.albedo / PI + vec3(fresnel * specular);
  vec3 metal = specular * (s.albedo + (1.0 - s.albedo) * schlick);
  return ((1.0 - s.metallic) * dielectric + s.metallic * metal) * l.z;
}

float metallic_roughness_pdf(Surface s, vec3 wo, vec3 wi) {
  if (wo.z <= 0.0 || wi.z == 0.0) return 0.0;
  vec2 alpha = vec2(metallic_roughness_alpha(s));
  vec3 l = vec3(wi.xy, abs(wi.z)), h = normalize(wo + l);
  vec2 p = lobe_shares(s, wo);
  float specular = ggx_density(h, alpha) * smith_masking(wo, h, alpha) / (4.0 * wo.z);
  if (wi.z < 0.0) return p.y * specular;
  return p.x * specular + max(0.0, 1.0 - p.x - p.y) * wi.z / PI;  // (with transmission 1, 0 up to rounding)
}

// Whether the surface is no interface at all (a rough dielectric of index 1, which sample_bsdf passes
// straight on): the direct model passes the ray on there, as at a delta BSDF, instead of shading it.
bool passes_straight_on(Surface s) {
  return SCENE_HAS_roughdielectric && s.material_type == VKRAY_MATERIAL_ROUGHDIELECTRIC && s.ior == 1.0;
}

// ---- The three functions -----------------------------------------------------------------------------

// f(wo, wi) |n . wi|; 0 for delta BSDFs and directions a lobe does not reach.
vec3 eval_bsdf(Surface s, vec3 wo, vec3 wi, vec3 n, bool front) {
  if (!SCENE_HAS_NON_DIFFUSE || s.material_type == VKRAY_MATERIAL_DIFFUSE) return s.albedo * (max(0.0, dot(wi, n)) / PI);
  vec3 o = to_tangent_space(wo, n), i = to_tangent_space(wi, n);  // once, for whichever lobe it is
  if (SCENE_HAS_roughconductor && s.material_type == VKRAY_MATERIAL_ROUGHCONDUCTOR) return conductor_eval(s, o, i);
  if (SCENE_HAS_roughdielectric && s.material_type == VKRAY_MATERIAL_ROUGHDIELECTRIC)
    return dielectric_eval(s, o, i, front ? s.ior : 1.0 / s.ior);
  if (SCENE_HAS_metallic_roughness && s.material_type == VKRAY_MATERIAL_METALLIC_ROUGHNESS) return metallic_roughness_eval(s, o, i);
  return vec3(0.0);
}

// The solid-angle density with which sample_bsdf picks wi; 0 for delta BSDFs.
float pdf_bsdf(Surface s, vec3 wo, vec3 wi, vec3 n, bool front) {
  if (!SCENE_HAS_NON_DIFFUSE || s.material_type == VKRAY_MATERIAL_DIFFUSE) return max(0.0, dot(wi, n)) / PI;
  vec3 o = to_tangent_space(wo, n), i = to_tangent_space(wi, n);
  if (SCENE_HAS_roughconductor && s.material_type == VKRAY_MATERIAL_ROUGHCONDUCTOR) return conductor_pdf(s, o, i);
  if (SCENE_HAS_roughdielectric && s.material_type == VKRAY_MATERIAL_ROUGHDIELECTRIC)
    return dielectric_pdf(s, o, i, front ? s.ior : 1.0 / s.ior);
  if (SCENE_HAS_metallic_roughness && s.material_type == VKRAY_MATERIAL_METALLIC_ROUGHNESS) return metallic_roughness_pdf(s, o, i);
  return 0.0;
}

// The direction is normalized again: the ray tests assume a unit direction, and a sphere's normal,
// from a hit point a float rounding off the surface, is not quite unit; unchecked, the error grew
// bounce by bounce until paths in a closed sphere left it (0.4% of the light lost by 60 bounces,
// 2026-11-23).
BsdfSample sample_bsdf(Surface s, vec3 wo, vec3 n, bool front, inout uint stream) {
  BsdfSample b;
  b.delta = (s.properties & VKRAY_BSDF_DELTA) != 0u;
  b.transmitted = false;
  b.eta = 1.0;
  b.pdf = 0.0;
  if (!SCENE_HAS_NON_DIFFUSE || s.material_type == VKRAY_MATERIAL_DIFFUSE) {
    vec2 u = vec2(next_random(stream), next_random(stream));
    vec3 local = cosine_hemisphere(u);
    b.dir = normalize(to_world(local, n));
    b.pdf = local.z / PI;
    b.weight = s.albedo;
    return b;
  }
  if (SCENE_HAS_roughconductor && s.material_type == VKRAY_MATERIAL_ROUGHCONDUCTOR) {
    vec2 u = vec2(next_random(stream), next_random(stream));
    vec3 o = to_tangent_space(wo, n);
    b.dir = n;
    b.weight = vec3(0.0);
    if (o.z <= 0.0) return b;  // seen from below its shading normal: no light
    vec3 m = sample_visible_normal(o, s.alpha, u);
    vec3 i = 2.0 * dot(o, m) * m - o;
    if (i.z <= 0.0) return b;  // reflected below the surface
    b.dir = normalize(from_tangent_space(i, n));
    b.pdf = conductor_pdf(s, o, i);
    // f cos / pdf = F G1(wi): D, G1(wo) and the cosines cancel.
    b.weight = s.albedo * fresnel_conductor(dot(o, m), s.eta, s.k) * smith_masking(i, m, s.alpha);
    return b;
  }
  if (SCENE_HAS_roughdielectric && s.material_type == VKRAY_MATERIAL_ROUGHDIELECTRIC) {
    vec2 u = vec2(next_random(stream), next_random(stream));
    float u_choice = next_random(stream);
    float eta = front ? s.ior : 1.0 / s.ior;
    if (eta == 1.0) {  // no interface: straight on, whole
      b.delta = true;
      b.transmitted = true;
      b.dir = -wo;
      b.weight = vec3(1.0);
      return b;
    }
    vec3 o = to_tangent_space(wo, n);
    b.dir = n;
    b.weight = vec3(0.0);
    if (o.z <= 0.0) return b;
    vec3 m = sample_visible_normal(o, s.alpha, u);
    float cos_i = dot(o, m);
    float cos_t;
    float f = fresnel_dielectric(cos_i, eta, cos_t);
    if (u_choice < f) {  // reflection, with probability F: f cos / pdf = G1(wi)
      vec3 i = 2.0 * cos_i * m - o;
      if (i.z <= 0.0) return b;
      b.dir = normalize(from_tangent_space(i, n));
      b.pdf = dielectric_pdf(s, o, i, eta);
      b.weight = vec3(smith_masking(i, m, s.alpha));
      return b;
    }
    // Refraction about m, with probability 1 - F: f cos / pdf = G1(wi) / eta^2.
    vec3 i = normalize((cos_i / eta - cos_t) * m - o / eta);
    if (i.z >= 0.0) return b;
    b.dir = normalize(from_tangent_space(i, n));
    b.pdf = dielectric_pdf(s, o, i, eta);
    b.transmitted = true;
    b.eta = eta;
    b.weight = vec3(smith_masking(i, m, s.alpha) / (eta * eta));
    return b;
  }
  if (SCENE_HAS_metallic_roughness && s.material_type == VKRAY_MATERIAL_METALLIC_ROUGHNESS) {
    float u_lobe = next_random(stream);
    vec2 u = vec2(next_random(stream), next_random(stream));
    vec3 o = to_tangent_space(wo, n);
    b.dir = n;
    b.weight = vec3(0.0);
    if (o.z <= 0.0) return b;
    vec3 i;
    vec2 p = lobe_shares(s, o);
    if (u_lobe < p.x + p.y) {  // a visible normal's reflection, mirrored through the surface to transmit
      vec3 m = sample_visible_normal(o, vec2(metallic_roughness_alpha(s)), u);
      i = 2.0 * dot(o, m) * m - o;
      if (i.z <= 0.0) return b;
      if (u_lobe >= p.x) i.z = -i.z;
    } else {
      i = cosine_hemisphere(u);
      if (i.z <= 0.0) return b;
    }
    // Any lobe may have given the direction: the weight is the whole BSDF over the mixed density.
    b.pdf = metallic_roughness_pdf(s, o, i);
    if (!(b.pdf > 0.0)) return b;
    b.dir = normalize(from_tangent_space(i, n));
    b.transmitted = i.z < 0.0;  // through a thin sheet: unbent, b.eta stays 1
    b.weight = metallic_roughness_eval(s, o, i) / b.pdf;
    return b;
  }
  if ((SCENE_HAS_mirror && s.material_type == VKRAY_MATERIAL_MIRROR) || (SCENE_HAS_glass && s.material_type == VKRAY_MATERIAL_GLASS)) {
    float cos_i = dot(wo, n);
    vec3 reflected = normalize(2.0 * cos_i * n - wo);
    if (SCENE_HAS_mirror && s.material_type == VKRAY_MATERIAL_MIRROR) {
      b.dir = reflected;
      b.weight = s.albedo;
      return b;
    }
    float eta = front ? s.ior : 1.0 / s.ior;
    float cos_t;
    float f = fresnel_dielectric(cos_i, eta, cos_t);
    if (next_random(stream) < f) {
      b.dir = reflected;
      b.weight = vec3(1.0);
      return b;
    }
    b.dir = normalize((cos_i / eta - cos_t) * n - wo / eta);
    b.transmitted = true;
    b.eta = eta;
    b.weight = vec3(1.0 / (eta * eta));  // radiance is compressed into the narrower cone
    return b;
  }
  b.dir = n;  // a type the scene has no material of: never reached
  b.weight = vec3(0.0);
  return b;
}

#endif
