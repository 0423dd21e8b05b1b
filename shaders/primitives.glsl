// The scene's primitives as the texel buffers hold them (shared/scene_layout.h): the ray test of
// one primitive, and the surface at a hit.
#ifndef VKRAY_PRIMITIVES_GLSL
#define VKRAY_PRIMITIVES_GLSL

#include "intersect.glsl"
#include "resources.glsl"
#include "texture.glsl"

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
  vec3 albedo;            // or a mirror's reflectance, its texture applied
  uint material_type;     // VKRAY_MATERIAL_*
  vec3 emission;          // its texture applied
  float ior;
  float light_pdf_area;   // the density per unit area with which light sampling picks this point (emitters.glsl)
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
  s.light_pdf_area = 0.0;
  if (SCENE_HAS_EMITTERS || SCENE_HAS_SPECULAR) {
    vec4 emission = texelFetch(materials, material_texel(flags) + VKRAY_MATERIAL_EMISSION);
    vec4 density = texelFetch(materials, material_texel(flags) + VKRAY_MATERIAL_LIGHT);
    s.emission = emission.rgb;
    s.ior = emission.w;
    s.light_pdf_area = density.x;
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
  bool smooth_normals = (flags & VKRAY_PRIM_SMOOTH) != 0u;
  vec4 albedo_texture = vec4(0.0), emission_texture = vec4(0.0);
  if (SCENE_HAS_TEXTURES) {
    albedo_texture = texelFetch(materials, material_texel(flags) + VKRAY_MATERIAL_ALBEDO_TEXTURE);
    emission_texture = texelFetch(materials, material_texel(flags) + VKRAY_MATERIAL_EMISSION_TEXTURE);
  }
  bool textured = SCENE_HAS_TEXTURES && (has_texture(albedo_texture) || has_texture(emission_texture));
  if (!smooth_normals && !textured) return s;
  vec2 b = triangle_barycentrics(position, a.xyz, v1, v2);
  if (smooth_normals)
    s.shading_normal = normalize((1.0 - b.x - b.y) * texelFetch(normals, base).xyz + b.x * texelFetch(normals, base + 1).xyz +
                                 b.y * texelFetch(normals, base + 2).xyz);
  if (textured) {
    vec2 uv = triangle_texcoord(hit.prim, b);
    if (has_texture(albedo_texture)) s.albedo *= sample_texture(albedo_texture, uv);
    if (has_texture(emission_texture)) s.emission *= sample_texture(emission_texture, uv);
  }
  return s;
}

#endif
