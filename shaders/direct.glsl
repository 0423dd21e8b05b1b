// The direct model (the default integrator): what a camera ray sees, lit by the lights directly
// (shade.glsl). Emitters seen are added; a mirror or glass surface passes the ray on, as a Whitted
// ray tracer does, up to VKRAY_SPECULAR_BOUNCES times, until it meets a surface that is not a delta
// (diffuse or glossy) or nothing.
#ifndef VKRAY_DIRECT_GLSL
#define VKRAY_DIRECT_GLSL

#include "aovs.glsl"
#include "bsdf.glsl"
#include "environment.glsl"
#include "shade.glsl"
#include "traversal.glsl"

// The radiance along a camera ray; adds the rays it traces after the camera ray to `rays`.
vec3 direct_radiance(Ray ray, inout uint stream, inout uint rays) {
  if (!SCENE_HAS_EMITTERS && !SCENE_HAS_NON_DIFFUSE) {  // the lecture's model: one hit, shaded
    Hit hit = trace_closest(ray, frame.epsilon, FAR, true, stream);
    if (hit.prim == NO_HIT) return background_radiance(ray.dir);
    vec3 x = ray_at(ray, hit.t);
    Surface s = hit_surface(hit, ray);
    if (FIRST_HIT_PASSES) add_first_hit(hit, x, s);
    return shade(ray, x, s, stream, rays);
  }
  vec3 radiance = vec3(0.0), throughput = vec3(1.0);
  uint bounce = 0u;
  do {
    Hit hit = trace_closest(ray, frame.epsilon, FAR, bounce == 0u, stream);
    if (hit.prim == NO_HIT) {
      radiance += throughput * background_radiance(ray.dir);
      break;
    }
    vec3 x = ray_at(ray, hit.t);
    Surface s = hit_surface(hit, ray);
    if (FIRST_HIT_PASSES && bounce == 0u) add_first_hit(hit, x, s);
    bool front = !(dot(s.geometric_normal, ray.dir) > 0.0);  // a grazing ray meets the front, as in shade()
    if (front || s.emits_both_sides) radiance += throughput * s.emission;
    if ((s.properties & VKRAY_BSDF_DELTA) == 0u && !passes_straight_on(s)) {
      radiance += throughput * shade(ray, x, s, stream, rays);
      break;
    }
    Facing f = facing(s, ray.dir, front);
    vec3 n_geometric = f.n_geometric, n = f.n;
    BsdfSample b = sample_bsdf(s, -ray.dir, n, front, stream);
    // A direction on the wrong side of the surface (an interpolated normal can point there) ends it.
    if ((dot(b.dir, n_geometric) > 0.0) == b.transmitted) break;
    throughput *= b.weight;
    ray = Ray(x + (b.transmitted ? -frame.epsilon : frame.epsilon) * n_geometric, b.dir);
    rays += 1u;
  } while (++bounce <= VKRAY_SPECULAR_BOUNCES);
  return radiance;
}

#endif
