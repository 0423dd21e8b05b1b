// The direct model: L = albedo (A + sum of point, spot and directional lights + one area-light sample + one
// environment-map sample) at the first diffuse
// surface (a glossy one: its BSDF against the same lights, the ambient term times its colour), emitters
// seen added, mirrors and glass followed up to VKRAY_SPECULAR_BOUNCES times.
#include <limits>

#include "cpu/bsdf.h"
#include "cpu/integrators.h"
#include "cpu/warp.h"
#include "shared/types.h"

namespace vkray::cpu {
namespace {

// The radiance a surface that is not a delta reflects toward the ray: the ambient term times its
// colour, and its BSDF against the point, spot and directional lights, one area-light sample and one
// environment-map sample. n, n_geometric face the
// incoming ray. For a diffuse surface, the scene contract's albedo (A + sum of lights + area light).
dvec3 shade(const Tracer& tracer, const Lights& lights, const SurfacePoint& s, const Bsdf& bsdf, const dvec3& wo, bool front,
            const dvec3& n, const dvec3& n_geometric, SampleState& state, bool first) {
  const Scene& scene = tracer.scene();
  const dvec3 x = s.position;
  dvec3 radiance = bsdf.color * dvec3(scene.ambient);
  const LitPoint p{x, n, n_geometric, x + tracer.epsilon() * n_geometric, x - tracer.epsilon() * n_geometric,
                   bsdf.has(VKRAY_BSDF_TRANSMISSION)};
  lights.add_delta_lights(p, bsdf, wo, front, radiance, first ? &state.signature : nullptr, state.stream, state.rays);
  if (lights.has_area_lights()) {
    const AreaLightSample light = lights.sample_area_light_from(p, state.stream, state.rays);
    if (light.pdf > 0) radiance += eval_bsdf(bsdf, wo, light.dir, n, front) * light.radiance / light.pdf;
  }
  if (lights.environment()) {  // the environment: one more light, sampled the same way
    const AreaLightSample light = lights.sample_environment_from(p, state.stream, state.rays);
    if (light.pdf > 0) radiance += eval_bsdf(bsdf, wo, light.dir, n, front) * light.radiance / light.pdf;
  }
  return radiance;
}

}  // namespace

dvec3 direct_radiance(const Tracer& tracer, const Lights& lights, const Ray& camera_ray, SampleState& state) {
  const Scene& scene = tracer.scene();
  const double epsilon = tracer.epsilon();
  Ray ray = camera_ray;
  dvec3 radiance(0.0), throughput(1.0);
  for (uint32_t bounce = 0; bounce <= VKRAY_SPECULAR_BOUNCES; ++bounce) {
    const double far = std::numeric_limits<double>::infinity();
    const Hit hit = bounce == 0 ? tracer.camera_hit(ray, epsilon, far, state.stream) : tracer.closest(ray, epsilon, far, state.stream);
    if (bounce == 0) mix(state.signature, uint64_t(int64_t(hit.primitive)));
    if (hit.primitive < 0) {
      radiance += throughput * lights.background(ray.dir);
      break;
    }
    const SurfacePoint s = tracer.surface(ray, hit);
    if (bounce == 0) add_first_hit(tracer, hit, s, state);
    const Material& material = scene.materials[s.material];
    // Both normals face the incoming ray, as the geometric one decides (a grazing ray meets the front).
    const bool front = !(glm::dot(s.geometric_normal, ray.dir) > 0);
    const auto [n_geometric, n] = facing(s, ray.dir, front);
    if (front || material.emits_both_sides) radiance += throughput * s.emission;
    const Bsdf bsdf = bsdf_of(material, s.albedo, s.metallic, s.roughness, s.transmission);
    if (!bsdf.has(VKRAY_BSDF_DELTA) && !passes_straight_on(bsdf)) {
      radiance += throughput * shade(tracer, lights, s, bsdf, -ray.dir, front, n, n_geometric, state, bounce == 0);
      break;
    }
    const BsdfSample b = sample_bsdf(bsdf, -ray.dir, n, front, state.stream);
    if ((glm::dot(b.dir, n_geometric) > 0) == b.transmitted) break;  // the wrong side of the surface
    throughput *= b.weight;
    ray = {s.position + (b.transmitted ? -epsilon : epsilon) * n_geometric, b.dir};
    ++state.rays;
  }
  return radiance;
}

}  // namespace vkray::cpu
