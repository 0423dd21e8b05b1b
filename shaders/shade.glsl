// Direct Lambertian shading from point lights plus an ambient term, exactly the scene contract:
//   L = albedo * (A + sum_lights V * I * (n . w) / (pi r^2))
// with n the normal facing the incoming ray (the interpolated vertex normal for smooth meshes, the
// geometric normal otherwise), w the unit vector to the light, r its distance, and V = 0 when the
// light is at most epsilon above the plane of n at x (n . (light - x) <= epsilon) or a shadow ray
// finds anything closer than the light.
#ifndef VKRAY_SHADE_GLSL
#define VKRAY_SHADE_GLSL

#include "primitives.glsl"
#include "resources.glsl"
#include "traversal.glsl"

const float PI = 3.14159265358979;

// Returns the radiance leaving the hit point toward the ray's origin; adds the shadow rays it casts
// to `rays`.
vec3 shade(Ray ray, Hit hit, inout uint rays) {
  vec3 x = ray_at(ray, hit.t);
  Surface surface = hit_surface(hit, x);
  // Both normals face the incoming ray, decided by the geometric one.
  bool flip = dot(surface.geometric_normal, ray.dir) > 0.0;
  vec3 n_geometric = flip ? -surface.geometric_normal : surface.geometric_normal;
  vec3 n = flip ? -surface.shading_normal : surface.shading_normal;

  // Shadow rays start a little off the surface, on the side the ray came from.
  vec3 shadow_origin = x + frame.epsilon * n_geometric;
  vec3 irradiance = frame.ambient.rgb;
  // A do-while without `continue`, as the sample loop in trace.comp: a loop that tests first costs
  // a masked pass more, and so does one with a `continue` (the compiler moves the test to the top
  // of the next pass, for every lane).
  uint i = 0u;
  if (frame.light_count > 0u) do {
    int base = int(i) * VKRAY_TEXELS_PER_LIGHT;
    vec3 light_pos = texelFetch(lights, base + VKRAY_LIGHT_POSITION).xyz;
    vec3 to_light = light_pos - x;
    float r2 = dot(to_light, to_light);
    float cos_theta = dot(n, to_light * inversesqrt(r2));
    // Lit only by a light more than epsilon above the plane of n at x (the contract's height rule:
    // a light on the surface, or at x itself, lights nothing there, whatever the rounding of x).
    bool lit = dot(n, to_light) > frame.epsilon;
    if (SHADOW_RAYS && lit) {
      vec3 shadow_dir = light_pos - shadow_origin;
      float shadow_dist = length(shadow_dir);
      rays += 1u;
      // Stop epsilon short of the light so a light lying on a surface is not hidden by that surface.
      lit = !trace_any(Ray(shadow_origin, shadow_dir / shadow_dist), frame.epsilon, shadow_dist - frame.epsilon);
    }
    if (lit) irradiance += texelFetch(lights, base + VKRAY_LIGHT_INTENSITY).rgb * (cos_theta / (PI * r2));
  } while (++i < frame.light_count);
  return surface.albedo * irradiance;
}

#endif
