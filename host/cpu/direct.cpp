// The direct model: L = albedo (A + sum of point lights + one area-light sample) at the first diffuse
// surface, emitters seen added, mirrors and glass followed up to VKRAY_SPECULAR_BOUNCES times.
#include <limits>

#include "cpu/bsdf.h"
#include "cpu/integrators.h"
#include "cpu/warp.h"
#include "shared/types.h"

namespace vkray::cpu {
namespace {

// The radiance a diffuse surface reflects toward the ray; n, n_geometric face the incoming ray.
dvec3 shade(const Tracer& tracer, const Lights& lights, const SurfacePoint& s, const dvec3& n, const dvec3& n_geometric,
            SampleState& state, bool first) {
  const Scene& scene = tracer.scene();
  const dvec3 x = s.position;
  dvec3 irradiance(scene.ambient);
  const dvec3 shadow_origin = x + tracer.epsilon() * n_geometric;
  lights.add_point_lights(x, n, shadow_origin, irradiance, first ? &state.signature : nullptr, state.rays);
  if (lights.has_area_lights()) {
    const AreaLightSample light = lights.sample_area_light_from(x, n, shadow_origin, state.stream, state.rays);
    if (light.pdf > 0) irradiance += light.radiance * (light.cos_x / (kPi * light.pdf));
  }
  return s.albedo * irradiance;
}

}  // namespace

dvec3 direct_radiance(const Tracer& tracer, const Lights& lights, const Ray& camera_ray, SampleState& state) {
  const Scene& scene = tracer.scene();
  const double epsilon = tracer.epsilon();
  Ray ray = camera_ray;
  dvec3 radiance(0.0), throughput(1.0);
  for (uint32_t bounce = 0; bounce <= VKRAY_SPECULAR_BOUNCES; ++bounce) {
    const Hit hit = tracer.closest(ray, epsilon, std::numeric_limits<double>::infinity());
    if (bounce == 0) mix(state.signature, uint64_t(int64_t(hit.primitive)));
    if (hit.primitive < 0) {
      radiance += throughput * dvec3(scene.background);
      break;
    }
    const SurfacePoint s = tracer.surface(ray, hit);
    if (bounce == 0) add_first_hit(tracer, hit, s, state);
    const Material& material = scene.materials[s.material];
    // Both normals face the incoming ray, as the geometric one decides (a grazing ray meets the front).
    const bool front = !(glm::dot(s.geometric_normal, ray.dir) > 0);
    const dvec3 n_geometric = front ? s.geometric_normal : -s.geometric_normal;
    const dvec3 n = front ? s.shading_normal : -s.shading_normal;
    if (front) radiance += throughput * s.emission;
    if (!material.specular()) {
      radiance += throughput * shade(tracer, lights, s, n, n_geometric, state, bounce == 0);
      break;
    }
    const BsdfSample b = sample_bsdf(material, s.albedo, -ray.dir, n, front, state.stream);
    if ((glm::dot(b.dir, n_geometric) > 0) == b.transmitted) break;  // the wrong side of the surface
    throughput *= b.weight;
    ray = {s.position + (b.transmitted ? -epsilon : epsilon) * n_geometric, b.dir};
    ++state.rays;
  }
  return radiance;
}

}  // namespace vkray::cpu
