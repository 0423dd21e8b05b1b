// The materials' BSDFs (shared/materials.h names the types and their properties), each with eval,
// pdf and sample:
//   diffuse         Lambertian, albedo / pi, both sides; sampled by cosine (two numbers)
//   mirror          perfect specular reflection times the reflectance, both sides (no numbers)
//   glass           a smooth dielectric, ior inside and 1 outside (the geometric normal points out):
//                   Fresnel reflection or refraction, picked with probability F (one number)
// Every function takes wo, unit, back along the incoming ray; n, the shading normal turned to the
// ray's side; front, whether the ray met the side the geometric normal faces. The CPU reference
// implements the same (host/cpu/bsdf.h).
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

// ---- The three functions -----------------------------------------------------------------------------

// f(wo, wi) |n . wi|; 0 for delta BSDFs and directions a lobe does not reach.
vec3 eval_bsdf(Surface s, vec3 wo, vec3 wi, vec3 n, bool front) {
  if (!SCENE_HAS_NON_DIFFUSE || s.material_type == VKRAY_MATERIAL_DIFFUSE) return s.albedo * (max(0.0, dot(wi, n)) / PI);
  return vec3(0.0);
}

// The solid-angle density with which sample_bsdf picks wi; 0 for delta BSDFs.
float pdf_bsdf(Surface s, vec3 wo, vec3 wi, vec3 n, bool front) {
  if (!SCENE_HAS_NON_DIFFUSE || s.material_type == VKRAY_MATERIAL_DIFFUSE) return max(0.0, dot(wi, n)) / PI;
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
  float cos_i = dot(wo, n);
  vec3 reflected = normalize(2.0 * cos_i * n - wo);
  if (s.material_type == VKRAY_MATERIAL_MIRROR) {
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

#endif
