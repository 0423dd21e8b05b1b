// Path tracing, as the shader's path.glsl: next-event estimation at every vertex that is not a delta (every point,
// spot and directional light, one area-light sample, one environment-map or background sample) weighed by the power heuristic against BSDF
// sampling; Mitsuba's max_depth; Russian roulette from rr_depth.
#include <algorithm>
#include <limits>

#include "cpu/bsdf.h"
#include "cpu/integrators.h"
#include "cpu/warp.h"
#include "shared/sampling.h"

namespace vkray::cpu {
namespace {

constexpr double kBackgroundPdf = 1 / (4 * kPi);  // uniform over the sphere

double power_heuristic(double a, double b) { return (a * a) / (a * a + b * b); }

}  // namespace

dvec3 path_radiance(const Tracer& tracer, const Lights& lights, const Ray& camera_ray, SampleState& state) {
  const Scene& scene = tracer.scene();
  const double epsilon = tracer.epsilon();
  constexpr double kFar = std::numeric_limits<double>::infinity();
  const dvec3 background(scene.background);
  const bool background_sampled = scene.background != glm::vec3(0.0f);
  Ray ray = camera_ray;
  dvec3 radiance(0.0), throughput(1.0);
  bool after_delta = true;  // the camera, a mirror or glass: nothing to weigh a hit against
  double bsdf_pdf = 0;
  double eta_product = 1;
  // max_depth -1 is no limit; a path of max_depth vertices ends.
  const uint32_t max_depth = uint32_t(scene.integrator.max_depth);
  for (uint32_t depth = 0;;) {
    const Hit hit = depth == 0 ? tracer.camera_hit(ray, epsilon, kFar, state.stream) : tracer.closest(ray, epsilon, kFar, state.stream);
    if (depth == 0) mix(state.signature, uint64_t(int64_t(hit.primitive)));
    if (hit.primitive < 0) {
      if (const EnvironmentLight* environment = lights.environment()) {
        const EnvironmentLight::Lookup e = environment->lookup(ray.dir);
        const bool whole = after_delta || !lights.environment_sampled();  // nothing else could have found it
        radiance += throughput * e.radiance * (whole ? 1.0 : power_heuristic(bsdf_pdf, e.pdf));
      } else {
        radiance += throughput * background * (after_delta ? 1.0 : power_heuristic(bsdf_pdf, kBackgroundPdf));
      }
      break;
    }
    const SurfacePoint s = tracer.surface(ray, hit);
    if (depth == 0) add_first_hit(tracer, hit, s, state);
    const Material& material = scene.materials[s.material];
    const double cos_hit = -glm::dot(s.geometric_normal, ray.dir);
    const bool front = cos_hit > 0;
    const double cos_emitting = material.emits_both_sides ? std::abs(cos_hit) : cos_hit;  // at the side that sends the light
    if (cos_emitting > 0 && material.emissive()) {
      const double light_pdf = lights.area_pdf(material.emission) * hit.t * hit.t / cos_emitting;
      radiance += throughput * s.emission * (after_delta ? 1.0 : power_heuristic(bsdf_pdf, light_pdf));
    }
    if (++depth >= max_depth) break;

    const auto [n_geometric, n] = facing(s, ray.dir, front);
    const dvec3 x = s.position;
    const dvec3 origin = x + epsilon * n_geometric;
    const Bsdf bsdf = bsdf_of(material, s.albedo, s.metallic, s.roughness, s.transmission);
    const dvec3 wo = -ray.dir;
    if (!bsdf.has(VKRAY_BSDF_DELTA)) {
      // Next-event estimation: each term f cos times the light over its density, weighed against BSDF sampling.
      const LitPoint p{x, n, n_geometric, origin, x - epsilon * n_geometric, bsdf.has(VKRAY_BSDF_TRANSMISSION)};
      dvec3 from_points(0.0);
      lights.add_delta_lights(p, bsdf, wo, front, from_points, depth == 1 ? &state.signature : nullptr, state.stream, state.rays);
      radiance += throughput * from_points;
      if (lights.has_area_lights()) {
        const AreaLightSample light = lights.sample_area_light_from(p, state.stream, state.rays);
        if (light.pdf > 0)
          radiance += throughput * eval_bsdf(bsdf, wo, light.dir, n, front) * light.radiance *
                      (power_heuristic(light.pdf, pdf_bsdf(bsdf, wo, light.dir, n, front)) / light.pdf);
      }
      if (lights.environment()) {
        if (lights.environment_sampled()) {  // (otherwise found by BSDF sampling alone)
          const AreaLightSample light = lights.sample_environment_from(p, state.stream, state.rays);
          if (light.pdf > 0)
            radiance += throughput * eval_bsdf(bsdf, wo, light.dir, n, front) * light.radiance *
                        (power_heuristic(light.pdf, pdf_bsdf(bsdf, wo, light.dir, n, front)) / light.pdf);
        }
      } else if (background_sampled) {
        const double u1 = gpu::next_random(state.stream), u2 = gpu::next_random(state.stream);
        const dvec3 w = uniform_sphere(u1, u2);
        if (p.faces(w)) {
          ++state.rays;
          if (!tracer.occluded({p.origin_toward(w), w}, epsilon, kFar, state.stream))
            radiance += throughput * eval_bsdf(bsdf, wo, w, n, front) * background *
                        (power_heuristic(kBackgroundPdf, pdf_bsdf(bsdf, wo, w, n, front)) / kBackgroundPdf);
        }
      }
    }

    // The next direction.
    const BsdfSample b = sample_bsdf(bsdf, wo, n, front, state.stream);
    if ((glm::dot(b.dir, n_geometric) > 0) == b.transmitted) break;  // the wrong side of the surface
    throughput *= b.weight;
    if (std::max({throughput.r, throughput.g, throughput.b}) == 0) break;
    after_delta = b.delta;
    bsdf_pdf = b.pdf;
    eta_product *= b.eta;
    ray = {b.transmitted ? x - epsilon * n_geometric : origin, b.dir};
    ++state.rays;

    // Russian roulette: survive with probability q, weighted 1 / q.
    if (depth >= scene.integrator.rr_depth) {
      const double q = std::min(std::max({throughput.r, throughput.g, throughput.b}) * eta_product * eta_product, 0.95);
      if (!(gpu::next_random(state.stream) < q)) break;
      throughput /= q;
    }
  }
  return radiance;
}

}  // namespace vkray::cpu
