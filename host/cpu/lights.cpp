#include "cpu/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cpu/texture.h"
#include "cpu/warp.h"
#include "shared/sampling.h"
#include "shared/scene_layout.h"

namespace vkray::cpu {

Lights::Lights(const Tracer& tracer, bool shadows, bool sample_environment)
    : tracer_(tracer), shadows_(shadows), sample_environment_(sample_environment), epsilon_(tracer.epsilon()), table_(build_emitter_table(tracer.scene())) {
  if (!table_.entries.empty()) inv_weight_ = 1 / table_.total_weight;
  if (tracer.scene().environment) environment_.emplace(*tracer.scene().environment);
}

dvec3 Lights::background(const dvec3& dir) const {
  return environment() ? environment_->lookup(dir).radiance : dvec3(tracer_.scene().background);
}

AreaLightSample Lights::sample_environment_from(const LitPoint& p, uint32_t& stream, uint64_t& rays) const {
  const double u_row = gpu::next_random(stream), u_column = gpu::next_random(stream);
  const EnvironmentLight::Sample e = environment_->sample(u_row, u_column);
  AreaLightSample s;
  s.dir = e.dir;
  s.cos_x = glm::dot(p.n, e.dir);
  if (!(e.pdf > 0 && p.faces(e.dir))) return s;
  if (shadows_) {
    ++rays;
    if (tracer_.occluded({p.origin_toward(e.dir), e.dir}, epsilon_, std::numeric_limits<double>::infinity(), stream)) return s;
  }
  s.radiance = e.radiance;
  s.pdf = e.pdf;
  return s;
}

namespace {

// How much of a spot's intensity leaves at `angle` (radians) from its axis, from the angles as the
// scene gives them.
double spot_falloff(const Light& light, double angle) {
  const double cutoff = light.cutoff_angle, beam = light.beam_width;
  if (light.falloff == Light::Falloff::gltf) {
    // KHR_lights_punctual: a ramp in the cosine from the outer cone to the inner, squared.
    const double ramp = (std::cos(angle) - std::cos(cutoff)) / std::max(0.001, std::cos(beam) - std::cos(cutoff));
    return std::pow(std::clamp(ramp, 0.0, 1.0), 2);
  }
  // Mitsuba's spot: whole within the beam width, none past the cutoff, linear in the angle between.
  if (angle >= cutoff) return 0;
  return angle <= beam ? 1 : (cutoff - angle) / (cutoff - beam);
}

}  // namespace

void Lights::add_delta_lights(const LitPoint& p, const Bsdf& bsdf, const dvec3& wo, bool front, dvec3& radiance, uint64_t* signature,
                              uint32_t& stream, uint64_t& rays) const {
  const Scene& scene = tracer_.scene();
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    const dvec3 intensity(light.intensity);
    if (light.type == Light::Type::directional) {
      // The same direction at every point: the shadow ray goes on past the scene.
      const dvec3 w = -dvec3(light.direction);
      if (!p.faces(w)) continue;
      if (shadows_) {
        ++rays;
        if (tracer_.occluded({p.origin_toward(w), w}, epsilon_, std::numeric_limits<double>::infinity(), stream)) continue;
      }
      if (signature) mix(*signature, 0x8000000000000000ull | l);
      radiance += eval_bsdf(bsdf, wo, w, p.n, front) * intensity;
      continue;
    }
    const dvec3 position(light.position);
    const dvec3 to_light = position - p.x;
    const double r2 = glm::dot(to_light, to_light);
    // The light must stand more than epsilon above the plane of the normal (or below it, for a BSDF
    // that transmits): one on the surface (or at x) lights nothing there.
    const double height = glm::dot(p.n, to_light);
    if (!(height > epsilon_ || (p.both_sides && height < -epsilon_)) || !p.faces(to_light)) continue;
    if (shadows_) {
      ++rays;
      const dvec3& origin = p.origin_toward(to_light);
      const dvec3 shadow = position - origin;
      const double distance = glm::length(shadow);
      if (tracer_.occluded({origin, shadow / distance}, epsilon_, distance - epsilon_, stream)) continue;
    }
    if (signature) mix(*signature, 0x8000000000000000ull | l);
    const dvec3 w = to_light / std::sqrt(r2);
    double falloff = 1;
    if (light.type == Light::Type::spot) {
      const double c = std::clamp(glm::dot(glm::normalize(dvec3(light.direction)), -w), -1.0, 1.0);
      falloff = spot_falloff(light, std::acos(c));
    }
    radiance += eval_bsdf(bsdf, wo, w, p.n, front) * intensity * falloff / r2;
  }
}

AreaLightSample Lights::sample_area_light_from(const LitPoint& p, uint32_t& stream, uint64_t& rays) const {
  const LightPoint light = sample_area_light(stream);
  const dvec3 to_light = light.position - p.x;
  const double r2 = glm::dot(to_light, to_light);
  const dvec3 w = to_light / std::sqrt(r2);
  AreaLightSample s;
  s.dir = w;
  s.cos_x = glm::dot(p.n, w);
  const double cos_l = light.both_sides ? std::abs(glm::dot(light.normal, w)) : -glm::dot(light.normal, w);
  if (!(p.faces(w) && cos_l > 0)) return s;
  if (shadows_) {
    ++rays;
    const dvec3& origin = p.origin_toward(w);
    const dvec3 d = light.position - origin;
    const double distance = glm::length(d);
    // Stopped epsilon short of the light: the surface the point lies on is not in the way.
    if (tracer_.occluded({origin, d / distance}, epsilon_, distance - epsilon_, stream)) return s;
  }
  s.radiance = light.radiance;
  s.pdf = light.pdf_area * r2 / cos_l;
  return s;
}

LightPoint Lights::sample_area_light(uint32_t& stream) const {
  const Scene& scene = tracer_.scene();
  const float u_pick = gpu::next_random(stream);
  const double u1 = gpu::next_random(stream), u2 = gpu::next_random(stream);
  const uint32_t count = uint32_t(table_.entries.size());
  const uint32_t entry = gpu::alias_entry(u_pick, count);
  const EmitterTable::Entry& e = table_.entries[entry];
  const uint64_t p = table_.entries[gpu::alias_keeps_entry(u_pick, count, entry, e.probability) ? entry : e.alias].primitive;

  LightPoint light;
  uint32_t material;
  dvec3 b(0.0);  // the barycentrics of a point on a triangle
  const PrimitiveNumbering::Placed placed = tracer_.numbering().at(p);
  if (placed.triangle) {
    // In an instance, a point uniform on the mesh's triangle is uniform on the placed one too (an
    // affine map scales every area of a triangle alike); its normal turns by the inverse transpose.
    const Triangle& t = *placed.triangle;
    b = uniform_triangle(u1, u2);
    light.position = b.x * dvec3(t.v[0]) + b.y * dvec3(t.v[1]) + b.z * dvec3(t.v[2]);
    light.normal = glm::normalize(glm::cross(dvec3(t.v[1]) - dvec3(t.v[0]), dvec3(t.v[2]) - dvec3(t.v[0])));
    if (placed.instance >= 0) {
      light.position = tracer_.point_to_world(placed.instance, light.position);
      light.normal = tracer_.normal_to_world(placed.instance, light.normal);
    }
    material = t.material;
  } else {
    const Sphere& s = *placed.sphere;
    const dvec3 d = uniform_sphere(u1, u2);
    light.position = dvec3(s.center) + double(s.radius) * d;
    light.normal = s.inward ? -d : d;
    material = s.material;
  }
  // The light is picked by its material's emission; a texture only scales what the point sends.
  const Material& m = scene.materials[material];
  light.radiance = dvec3(m.emission);
  light.pdf_area = area_pdf(m.emission);
  light.both_sides = m.emits_both_sides;
  if (placed.triangle && m.emission_texture.present())
    light.radiance *= sample_texture(scene, m.emission_texture, triangle_texcoord(*placed.triangle, m.emission_texture, b.y, b.z));
  // An unlit emitter's vertex colours are part of its base colour, which it emits.
  if (placed.triangle && m.vertex_colours_emit && placed.triangle->coloured())
    light.radiance *= dvec3(vertex_colour(*placed.triangle, b.y, b.z));
  // Of a see-through emitter, only the part that is there sends light.
  if (placed.triangle ? scene.see_through(*placed.triangle) : m.see_through())
    light.radiance *= double(gpu::alpha_coverage(uint32_t(m.alpha_mode), float(opacity_at(scene, placed, b.y, b.z)), m.alpha_cutoff));
  return light;
}

double Lights::area_pdf(const glm::vec3& emission) const {
  return (0.2126 * emission.r + 0.7152 * emission.g + 0.0722 * emission.b) * inv_weight_;
}

}  // namespace vkray::cpu
