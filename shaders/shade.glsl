// Direct shading from point, spot and directional lights plus an ambient term; for a Lambertian surface
// exactly the scene contract:
//   L = albedo * (A + sum_lights V * I * (n . w) / (pi r^2) + one area-light sample + one environment sample)
// with n the shading normal facing the incoming ray (facing() below: the interpolated vertex normal
// for smooth meshes, the geometric normal otherwise, turned by a normal map), w the unit vector to the
// light, r its distance, and V = 0 when the light is at most epsilon above the plane of n at x
// (n . (light - x) <= epsilon), below the geometric plane at x (shading normals let no light through
// a surface), or a shadow ray finds anything closer than the light. A spot light's I is times its
// falloff; a directional light gives its irradiance E in place of I / r^2, its V by a shadow ray
// that goes on past the scene. Any other surface that is not a delta: the ambient term times
// its colour, and its BSDF f(wo, w) (n . w) in place of albedo (n . w) / pi. The path integrator
// (path.glsl) uses the same light terms.
#ifndef VKRAY_SHADE_GLSL
#define VKRAY_SHADE_GLSL

#include "bsdf.glsl"
#include "emitters.glsl"
#include "environment.glsl"
#include "primitives.glsl"
#include "resources.glsl"
#include "traversal.glsl"
#include "warp.glsl"

// ---- The side a ray meets ------------------------------------------------------------------------------
// The shading normal n bent toward the geometric normal ng (both on wo's side) just enough that the
// mirror reflection of wo about it leaves the surface at least min(0.9 (ng . wo), 0.01) above it in
// cosine: Cycles' rule for shading normals that face away from the viewer (a normal map's steep
// slopes, a coarse mesh's vertex normals at its silhouette), which would otherwise reflect into the
// surface and shade black. n itself where its reflection already leaves. With N = x X + z ng (X the
// unit part of n across ng) the condition 2 (N . wo) z - (ng . wo) = threshold is a quadratic in z^2;
// its one root that solves it before squaring. Applied to materials with a glossy or delta lobe, as
// Cycles applies it to its specular closures: a Lambertian surface's shading does not depend on wo,
// and light above n but below the surface is refused anyway (faces()).
vec3 valid_reflection_normal(vec3 ng, vec3 wo, vec3 n) {
  float iz = dot(wo, ng);
  float threshold = min(0.9 * iz, 0.01);
  // The reflection 2 (n . wo) n - wo rises 2 (n . wo)(n . ng) - iz above the surface. (Scalars where
  // they do: on llvmpipe every lane runs the bend below whether it needs it or not.)
  float n_wo = dot(n, wo), n_ng = dot(n, ng);
  if (2.0 * n_wo * n_ng - iz >= threshold) return n;
  vec3 across = n - n_ng * ng;
  float across2 = dot(across, across);
  float inv_across = across2 > 0.0 ? inversesqrt(across2) : 0.0;
  float ix = (n_wo - n_ng * iz) * inv_across;  // wo . across / |across|
  float a = ix * ix + iz * iz;
  if (!(across2 > 0.0) || !(a > 0.0)) return ng;
  float b = 2.0 * (a + iz * threshold);
  float c = (threshold + iz) * (threshold + iz);
  float root = sqrt(max(b * b - 4.0 * a * c, 0.0));
  float z2 = clamp(0.25 * (ix < 0.0 ? b + root : b - root) / a, 0.0, 1.0);
  return (sqrt(1.0 - z2) * inv_across) * across + sqrt(z2) * ng;
}

// A surface as a ray along `dir` meets it: on its front (the side its geometric normal faces, as the
// caller decides it), its two normals turned toward the ray, the shading one made valid for it where
// the material is not purely Lambertian.
struct Facing {
  vec3 n_geometric;
  vec3 n;
};

Facing facing(Surface s, vec3 dir, bool front) {
  vec3 ng = front ? s.geometric_normal : -s.geometric_normal;
  vec3 n = front ? s.shading_normal : -s.shading_normal;
  bool bend = SCENE_HAS_SHADING_NORMALS && SCENE_HAS_NON_DIFFUSE && s.properties != VKRAY_BSDF_DIFFUSE;
  return Facing(ng, bend ? valid_reflection_normal(ng, -dir, n) : n);
}

// A point lit by the lights: x, its shading normal n turned toward the incoming ray, and where its
// shadow rays leave: epsilon off the surface on the ray's side, or, for a BSDF that transmits (lit
// from behind too), on the side of the light.
struct LitPoint {
  vec3 x;
  vec3 n;
  vec3 n_geometric;   // turned as n is
  vec3 origin_front;  // x + epsilon n_geometric
  vec3 origin_back;   // x - epsilon n_geometric
  bool both_sides;
};

LitPoint lit_point(vec3 x, vec3 n, vec3 n_geometric, Surface s) {
  bool transmits = SCENE_HAS_NON_DIFFUSE && (s.properties & VKRAY_BSDF_TRANSMISSION) != 0u;
  return LitPoint(x, n, n_geometric, x + frame.epsilon * n_geometric, x - frame.epsilon * n_geometric, transmits);
}

// Whether light from direction w can reach the BSDF: above both n and the geometric surface; or, for
// a BSDF that transmits, on either side where the shading and geometric normals agree on the side
// (where they do not, the BSDF's own sampling ends the path too, so light sampling must not count it
// either).
bool faces(LitPoint p, vec3 w) {
  float c = dot(p.n, w);
  bool above = dot(p.n_geometric, w) > 0.0;
  if (!p.both_sides) return c > 0.0 && above;
  return c != 0.0 && (c > 0.0) == above;
}
vec3 origin_toward(LitPoint p, vec3 w) { return p.both_sides && dot(p.n_geometric, w) < 0.0 ? p.origin_back : p.origin_front; }

// One area-light sample as a point p sees it. Draws three numbers from the stream.
struct AreaLightSample {
  vec3 radiance;  // 0 when the point is behind x's side, faces away, or is hidden
  vec3 dir;       // unit, from x to the point
  float cos_x;    // at x, to the point (negative: behind, for a BSDF that transmits)
  float pdf;      // per unit solid angle at x
};

AreaLightSample sample_area_light_from(LitPoint p, inout uint stream, inout uint rays) {
  LightPoint light = sample_area_light(stream);
  vec3 to_light = light.position - p.x;
  float r2 = dot(to_light, to_light);
  vec3 w = to_light * inversesqrt(r2);
  float cos_l = light.both_sides ? abs(dot(light.normal, w)) : -dot(light.normal, w);
  AreaLightSample s = AreaLightSample(vec3(0.0), w, dot(p.n, w), 0.0);
  if (!(faces(p, w) && cos_l > 0.0)) return s;
  if (SHADOW_RAYS) {
    vec3 shadow_origin = origin_toward(p, w);
    vec3 shadow_dir = light.position - shadow_origin;
    float shadow_dist = length(shadow_dir);
    rays += 1u;
    // Stop epsilon short of the light: the surface the point lies on is not in the way.
    if (trace_any(Ray(shadow_origin, shadow_dir / shadow_dist), frame.epsilon, shadow_dist - frame.epsilon, stream)) return s;
  }
  s.radiance = light.radiance;
  s.pdf = light.pdf_area * r2 / cos_l;
  return s;
}

// One direction drawn from the environment map as a point p sees it, in the same form. Draws two
// numbers from the stream.
AreaLightSample sample_environment_from(LitPoint p, inout uint stream, inout uint rays) {
  EnvironmentSample e = sample_environment(stream);
  AreaLightSample s = AreaLightSample(vec3(0.0), e.dir, dot(p.n, e.dir), 0.0);
  if (!(e.pdf > 0.0 && faces(p, e.dir))) return s;
  if (SHADOW_RAYS) {
    rays += 1u;
    if (trace_any(Ray(origin_toward(p, e.dir), e.dir), frame.epsilon, FAR, stream)) return s;
  }
  s.radiance = e.radiance;
  s.pdf = e.pdf;
  return s;
}

// How much of a spot's intensity leaves along a direction at cosine c to its axis (VKRAY_LIGHT_CONE).
float spot_falloff(uint kind, float c, vec4 cone) {
  if (kind == VKRAY_LIGHT_GLTF_SPOT) {
    float ramp = clamp(c * cone.x + cone.y, 0.0, 1.0);
    return ramp * ramp;
  }
  // Mitsuba's: 1 within the beam, 0 from the cutoff on, linear in the angle between.
  if (!(c > cone.x)) return 0.0;
  return c >= cone.y ? 1.0 : clamp((cone.z - acos(c)) * cone.w, 0.0, 1.0);  // (acos rounds: held to the ramp's range)
}

// Adds V f(wo, w) |n . w| times each light's arrival to `radiance`: I / r^2 from a point light, I
// times its falloff / r^2 from a spot, E from a directional light; the surface s at p, seen along wo.
// Adds the shadow rays it casts to `rays` (each draws its alpha key from the stream).
void add_delta_lights(LitPoint p, Surface s, vec3 wo, bool front, inout vec3 radiance, inout uint stream, inout uint rays) {
  // A do-while without `continue`, as the sample loop in trace.comp: a loop that tests first costs
  // a masked pass more, and so does one with a `continue` (the compiler moves the test to the top
  // of the next pass, for every lane).
  uint i = 0u;
  if (SCENE_HAS_POINT_LIGHTS && frame.light_count > 0u) do {
    int base = int(i) * VKRAY_TEXELS_PER_LIGHT;
    vec4 position = texelFetch(lights, base + VKRAY_LIGHT_POSITION);
    uint kind = floatBitsToUint(position.w);
    vec3 arriving = texelFetch(lights, base + VKRAY_LIGHT_INTENSITY).rgb;
    vec3 w, shadow_target;
    bool lit;
    float shadow_far = FAR;
    if (kind == VKRAY_LIGHT_DIRECTIONAL) {
      // From the same direction everywhere, past everything in the scene.
      w = -texelFetch(lights, base + VKRAY_LIGHT_DIRECTION).xyz;
      lit = faces(p, w);
    } else {
      vec3 to_light = position.xyz - p.x;
      float r2 = dot(to_light, to_light);
      w = to_light * inversesqrt(r2);
      // Lit only by a light more than epsilon above the plane of n at x (the contract's height rule:
      // a light on the surface, or at x itself, lights nothing there, whatever the rounding of x), or
      // below it for a BSDF that transmits.
      float height = dot(p.n, to_light);
      lit = (height > frame.epsilon || (p.both_sides && height < -frame.epsilon)) && faces(p, to_light);
      arriving /= r2;
      if (kind != VKRAY_LIGHT_POINT)
        arriving *= spot_falloff(kind, dot(texelFetch(lights, base + VKRAY_LIGHT_DIRECTION).xyz, -w), texelFetch(lights, base + VKRAY_LIGHT_CONE));
    }
    if (SHADOW_RAYS && lit) {
      vec3 shadow_origin = origin_toward(p, w);
      vec3 shadow_dir = w;
      if (kind != VKRAY_LIGHT_DIRECTIONAL) {
        shadow_dir = position.xyz - shadow_origin;
        float shadow_dist = length(shadow_dir);
        shadow_dir /= shadow_dist;
        // Stop epsilon short of the light so a light lying on a surface is not hidden by that surface.
        shadow_far = shadow_dist - frame.epsilon;
      }
      rays += 1u;
      lit = !trace_any(Ray(shadow_origin, shadow_dir), frame.epsilon, shadow_far, stream);
    }
    if (lit) radiance += eval_bsdf(s, wo, w, p.n, front) * arriving;
  } while (++i < frame.light_count);
}

// Returns the radiance a surface at x that is not a delta reflects toward the ray's origin; draws from
// the stream for an area light, and adds the shadow rays it casts to `rays`.
vec3 shade(Ray ray, vec3 x, Surface surface, inout uint stream, inout uint rays) {
  // Both normals face the incoming ray, decided by the geometric one.
  bool front = !(dot(surface.geometric_normal, ray.dir) > 0.0);
  Facing f = facing(surface, ray.dir, front);
  vec3 n_geometric = f.n_geometric, n = f.n;
  vec3 wo = -ray.dir;

  // Shadow rays start a little off the surface, on the side the ray came from (or the light's).
  LitPoint p = lit_point(x, n, n_geometric, surface);
  vec3 radiance = surface.albedo * frame.ambient.rgb;
  add_delta_lights(p, surface, wo, front, radiance, stream, rays);
  if (SCENE_HAS_EMITTERS) {  // one light sample: f cos Le / pdf
    AreaLightSample light = sample_area_light_from(p, stream, rays);
    if (light.pdf > 0.0) radiance += eval_bsdf(surface, wo, light.dir, n, front) * (light.radiance / light.pdf);
  }
  if (SCENE_HAS_ENVIRONMENT) {  // and one of the environment, the same way
    AreaLightSample light = sample_environment_from(p, stream, rays);
    if (light.pdf > 0.0) radiance += eval_bsdf(surface, wo, light.dir, n, front) * (light.radiance / light.pdf);
  }
  return radiance;
}

#endif
