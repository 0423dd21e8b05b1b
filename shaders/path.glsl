// The path integrator: the rendering equation by unidirectional path tracing, as Mitsuba 3's `path`.
// At every vertex that is not a delta (diffuse or glossy), next-event estimation: each point, spot and
// directional light, one area-light sample and one sample of the environment map (drawn by its
// radiance) or of the background (uniform, when it is not black), the last two weighed against BSDF
// sampling by the power heuristic; then the BSDF picks the next direction. A hit on an emitter (or a
// miss, on the environment or the background) adds its light weighed the same way, or whole after a
// mirror or glass.
// Depth counts as Mitsuba's max_depth does; Russian roulette from rr_depth on.
#ifndef VKRAY_PATH_GLSL
#define VKRAY_PATH_GLSL

#include "aovs.glsl"
#include "bsdf.glsl"
#include "emitters.glsl"
#include "shade.glsl"
#include "traversal.glsl"

// The background is sampled uniformly over the sphere of directions.
const float BACKGROUND_PDF = 1.0 / (4.0 * PI);

// The power heuristic (Veach 1997, beta = 2): the weight of a sample drawn with density `a` when
// density `b` could have drawn it too, a^2 / (a^2 + b^2). Written with the ratio of the smaller
// density to the larger, so that no square overflows: a small light seen at a grazing angle has a
// density past 1.8e19, whose square is infinite, and inf / inf would be NaN. An infinite density
// takes the whole weight; two zero densities (a sample neither strategy could draw) weigh 1.
float power_heuristic(float a, float b) {
  float larger = max(a, b);
  float r = min(a, b) / larger;
  float w_larger = 1.0 / (1.0 + r * r);
  return larger > 0.0 ? (a >= b ? w_larger : 1.0 - w_larger) : 1.0;
}

// A path under way: where it goes next and what it carries.
struct PathState {
  Ray ray;               // the next ray to trace
  vec3 radiance;         // the light the path has brought so far
  vec3 throughput;
  bool after_delta;      // the last bounce was the camera, a mirror or glass: no light sampling to weigh against
  float bsdf_pdf;        // the solid-angle density of the last bounce's direction
  float eta_product;     // the relative indices crossed: Russian roulette undoes their radiance scaling
  uint depth;
};

PathState start_path(Ray camera_ray) { return PathState(camera_ray, vec3(0.0), vec3(1.0), true, 0.0, 1.0, 0u); }

// Traces one vertex of the path. Returns true when the path has ended: its light is p.radiance.
// One vertex at a time, so that trace.comp can start a pixel's next sample as soon as its path ends
// instead of waiting, masked, for the longest path among the lanes it runs with.
bool path_step(inout PathState p, inout uint stream, inout uint rays) {
  bool background_sampled = SCENE_HAS_BACKGROUND && (frame.background.r > 0.0 || frame.background.g > 0.0 || frame.background.b > 0.0);
  Hit hit = trace_closest(p.ray, frame.epsilon, FAR, p.depth == 0u, stream);
  if (hit.prim == NO_HIT) {
    if (SCENE_HAS_ENVIRONMENT) {
      EnvironmentLookup e = environment_lookup(p.ray.dir);
      bool whole = p.after_delta || !ENVIRONMENT_SAMPLED;  // nothing else could have found it
      p.radiance += p.throughput * e.radiance * (whole ? 1.0 : power_heuristic(p.bsdf_pdf, e.pdf));
    } else {
      float weight = p.after_delta ? 1.0 : power_heuristic(p.bsdf_pdf, BACKGROUND_PDF);
      p.radiance += p.throughput * frame.background.rgb * weight;
    }
    return true;
  }
  vec3 x = ray_at(p.ray, hit.t);
  Surface s = hit_surface(hit, p.ray);
  if (FIRST_HIT_PASSES && p.depth == 0u) add_first_hit(hit, x, s);
  float cos_hit = -dot(s.geometric_normal, p.ray.dir);
  bool front = cos_hit > 0.0;
  float cos_emitting = s.emits_both_sides ? abs(cos_hit) : cos_hit;  // at the side that sends the light
  if (SCENE_HAS_EMITTERS && cos_emitting > 0.0 && s.emission != vec3(0.0)) {  // (0 * a grazing hit's infinite density is NaN)
    // Light sampling finds this point with density pdf_area t^2 / cos per unit solid angle.
    float light_pdf = s.light_pdf_area * hit.t * hit.t / cos_emitting;
    float weight = p.after_delta ? 1.0 : power_heuristic(p.bsdf_pdf, light_pdf);
    p.radiance += p.throughput * s.emission * weight;
  }
  // Mitsuba's depth: a path of max_depth vertices ends here (-1, as a uint, never does).
  if (++p.depth >= uint(frame.max_depth)) return true;

  Facing f = facing(s, p.ray.dir, front);
  vec3 n_geometric = f.n_geometric, n = f.n;
  vec3 origin = x + frame.epsilon * n_geometric;  // on the side the ray came from
  vec3 wo = -p.ray.dir;
  if (!SCENE_HAS_NON_DIFFUSE || (s.properties & VKRAY_BSDF_DELTA) == 0u) {
    // ---- Next-event estimation: f cos times the light over its density, weighed against BSDF sampling --
    LitPoint lit = lit_point(x, n, n_geometric, s);
    vec3 from_points = vec3(0.0);
    add_delta_lights(lit, s, wo, front, from_points, stream, rays);
    p.radiance += p.throughput * from_points;
    if (SCENE_HAS_EMITTERS) {
      AreaLightSample light = sample_area_light_from(lit, stream, rays);
      if (light.pdf > 0.0)
        p.radiance += p.throughput * eval_bsdf(s, wo, light.dir, n, front) * light.radiance *
                      (power_heuristic(light.pdf, pdf_bsdf(s, wo, light.dir, n, front)) / light.pdf);
    }
    if (SCENE_HAS_ENVIRONMENT) {
      if (ENVIRONMENT_SAMPLED) {
        AreaLightSample light = sample_environment_from(lit, stream, rays);
        if (light.pdf > 0.0)
          p.radiance += p.throughput * eval_bsdf(s, wo, light.dir, n, front) * light.radiance *
                        (power_heuristic(light.pdf, pdf_bsdf(s, wo, light.dir, n, front)) / light.pdf);
      }
    } else if (background_sampled) {
      vec3 w = uniform_sphere(vec2(next_random(stream), next_random(stream)));
      if (faces(lit, w)) {
        rays += 1u;
        if (!trace_any(Ray(origin_toward(lit, w), w), frame.epsilon, FAR, stream))
          p.radiance += p.throughput * eval_bsdf(s, wo, w, n, front) * frame.background.rgb *
                        (power_heuristic(BACKGROUND_PDF, pdf_bsdf(s, wo, w, n, front)) / BACKGROUND_PDF);
      }
    }
  }

  // ---- The next direction ------------------------------------------------------------------------
  BsdfSample b = sample_bsdf(s, wo, n, front, stream);
  // A direction on the wrong side of the surface (an interpolated normal can point there) ends it.
  if ((dot(b.dir, n_geometric) > 0.0) == b.transmitted) return true;
  p.throughput *= b.weight;
  if (max(p.throughput.r, max(p.throughput.g, p.throughput.b)) == 0.0) return true;  // a black surface ends it
  p.after_delta = b.delta;
  p.bsdf_pdf = b.pdf;
  p.eta_product *= b.eta;
  p.ray = Ray(b.transmitted ? x - frame.epsilon * n_geometric : origin, b.dir);
  rays += 1u;

  // ---- Russian roulette: survive with probability q, weighted 1 / q ----------------------------------
  if (p.depth >= frame.rr_depth) {
    float q = min(max(p.throughput.r, max(p.throughput.g, p.throughput.b)) * p.eta_product * p.eta_product, 0.95);
    if (!(next_random(stream) < q)) return true;
    p.throughput /= q;
  }
  return false;
}

#endif
