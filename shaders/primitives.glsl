// The scene's primitives as the texel buffers hold them (shared/scene_layout.h): the ray test of
// one primitive, and the surface at a hit.
#ifndef VKRAY_PRIMITIVES_GLSL
#define VKRAY_PRIMITIVES_GLSL

#include "intersect.glsl"
#include "resources.glsl"

// t of the nearest intersection with the primitive in (t_min, t_max), or -1.
float intersect_primitive(Ray ray, RayShear shear, vec4 a, vec4 b, vec4 c, float t_min, float t_max) {
  if (SCENE_HAS_SPHERES && (primitive_flags(a) & VKRAY_PRIM_SPHERE) != 0u)
    return intersect_sphere(ray, a.xyz, sphere_radius(b), t_min, t_max);
  return intersect_triangle(ray, shear, a.xyz, b.xyz, c.xyz, t_min, t_max);
}

// ---- The surface at a hit -------------------------------------------------------------------------------
struct Surface {
  vec3 geometric_normal;  // unit, not yet oriented toward the ray: the side it faces emits
  vec3 shading_normal;    // unit: the geometric normal, or the interpolated vertex normal
  vec3 albedo;            // or a mirror's reflectance
  uint material_type;     // VKRAY_MATERIAL_*
  vec3 emission;
  float ior;
};

Surface hit_surface(Hit hit, vec3 position) {
  int base = int(hit.prim) * VKRAY_TEXELS_PER_PRIMITIVE;
  vec4 a = texelFetch(primitives, base);
  uint flags = primitive_flags(a);
  Surface s;
  vec4 color = texelFetch(materials, material_texel(flags) + VKRAY_MATERIAL_COLOR);
  s.albedo = color.rgb;
  s.material_type = floatBitsToUint(color.w);
  s.emission = vec3(0.0);
  s.ior = 1.0;
  if (SCENE_HAS_EMITTERS || SCENE_HAS_SPECULAR) {
    vec4 emission = texelFetch(materials, material_texel(flags) + VKRAY_MATERIAL_EMISSION);
    s.emission = emission.rgb;
    s.ior = emission.w;
  }
  if (SCENE_HAS_SPHERES && (flags & VKRAY_PRIM_SPHERE) != 0u) {
    s.geometric_normal = (position - a.xyz) / sphere_radius(texelFetch(primitives, base + 1));
    if ((flags & VKRAY_PRIM_INWARD) != 0u) s.geometric_normal = -s.geometric_normal;
    s.shading_normal = s.geometric_normal;
    return s;
  }
  vec3 v1 = texelFetch(primitives, base + 1).xyz, v2 = texelFetch(primitives, base + 2).xyz;
  s.geometric_normal = normalize(cross(v1 - a.xyz, v2 - a.xyz));
  s.shading_normal = s.geometric_normal;
  if ((flags & VKRAY_PRIM_SMOOTH) != 0u) {
    vec2 uv = triangle_barycentrics(position, a.xyz, v1, v2);
    s.shading_normal = normalize((1.0 - uv.x - uv.y) * texelFetch(normals, base).xyz + uv.x * texelFetch(normals, base + 1).xyz +
                                 uv.y * texelFetch(normals, base + 2).xyz);
  }
  return s;
}

#endif
