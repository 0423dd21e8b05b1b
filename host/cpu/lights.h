// The CPU reference's light sampling: every point, spot and directional light (the scene contract's
// term, with its height rule and shadow ray), and one point on an area light picked from the emitter table
// (scene/emitters.h) with the same numbers the shader draws (shaders/emitters.glsl).
#pragma once

#include <cstdint>
#include <optional>

#include "cpu/bsdf.h"
#include "cpu/environment.h"
#include "cpu/tracer.h"
#include "scene/emitters.h"

namespace vkray::cpu {

// FNV-1a over the 8 bytes of v: what a sample saw, hashed into a pixel's signature.
inline void mix(uint64_t& h, uint64_t v) {
  for (int i = 0; i < 8; ++i) h = (h ^ ((v >> (8 * i)) & 0xff)) * 0x100000001b3ull;
}

struct LightPoint {
  dvec3 position;
  dvec3 normal;       // unit, the side that emits (with both_sides, the other too)
  bool both_sides = false;
  dvec3 radiance;
  double pdf_area;    // density per unit area
};

// A point lit by the lights: x, its shading normal n turned toward the incoming ray, and where its
// shadow rays leave: epsilon off the surface on the ray's side, or, for a BSDF that transmits (lit
// from behind too), on the side of the light.
struct LitPoint {
  dvec3 x;
  dvec3 n;
  dvec3 n_geometric;       // turned as n is
  dvec3 origin_front;      // x + epsilon n_geometric
  dvec3 origin_back;       // x - epsilon n_geometric
  bool both_sides = false;

  // Whether light from direction w (unit or not) can reach the BSDF: above n and above the geometric
  // surface (no light through it); or, for a BSDF that transmits, on either side where the shading
  // and geometric normals agree on the side (where they do not, BSDF sampling ends the path, and
  // light sampling must not count it either).
  bool faces(const dvec3& w) const {
    const double c = glm::dot(n, w);
    const bool above = glm::dot(n_geometric, w) > 0;
    if (!both_sides) return c > 0 && above;
    return c != 0 && (c > 0) == above;
  }
  const dvec3& origin_toward(const dvec3& w) const { return both_sides && glm::dot(n_geometric, w) < 0 ? origin_back : origin_front; }
};

// One area-light sample as a point x sees it.
struct AreaLightSample {
  dvec3 radiance{0.0};  // 0 when the point is behind x's side, faces away, or is hidden
  dvec3 dir{0.0};       // unit, from x to the point
  double cos_x = 0;     // at x, to the point (negative: behind, for a BSDF that transmits)
  double pdf = 0;       // per unit solid angle at x
};

class Lights {
 public:
  // shadows false: every light counts as visible (benchmarks). sample_environment false: the
  // environment map is found by BSDF sampling alone (RenderOptions::sample_environment).
  Lights(const Tracer& tracer, bool shadows, bool sample_environment = true);

  // Adds V f(wo, w) |n . w| times what each light sends to x to `radiance`: I / r^2 from a point light
  // (for a diffuse surface, albedo V I (n . w) / (pi r^2), the scene contract's term), a spot's I times
  // its falloff / r^2, a directional light's irradiance E. Counts shadow rays in `rays` (each draws its
  // alpha key from `stream`); mixes each light that lights x into `signature` when given.
  void add_delta_lights(const LitPoint& p, const Bsdf& bsdf, const dvec3& wo, bool front, dvec3& radiance, uint64_t* signature,
                        uint32_t& stream, uint64_t& rays) const;

  bool has_area_lights() const { return !table_.entries.empty(); }
  // Draws three numbers: the light, then the point on it.
  LightPoint sample_area_light(uint32_t& stream) const;
  // The density per unit area with which sample_area_light finds a point emitting `emission`.
  double area_pdf(const glm::vec3& emission) const;
  // A point on the area lights (three numbers) as p sees it.
  AreaLightSample sample_area_light_from(const LitPoint& p, uint32_t& stream, uint64_t& rays) const;

  // The environment map, when the scene has one that sends light; null otherwise.
  const EnvironmentLight* environment() const { return environment_ && environment_->lights() ? &*environment_ : nullptr; }
  // What a ray that leaves the scene along `dir` brings: the environment's radiance, or the background.
  dvec3 background(const dvec3& dir) const;
  bool environment_sampled() const { return sample_environment_; }
  // A direction drawn from the environment (two numbers) as p sees it, in the area light's form.
  AreaLightSample sample_environment_from(const LitPoint& p, uint32_t& stream, uint64_t& rays) const;

 private:
  const Tracer& tracer_;
  bool shadows_;
  bool sample_environment_;
  double epsilon_;
  EmitterTable table_;
  double inv_weight_ = 0;
  std::optional<EnvironmentLight> environment_;
};

}  // namespace vkray::cpu
