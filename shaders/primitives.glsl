// The scene's primitives as the texel buffers hold them (shared/scene_layout.h): the ray test of
// one primitive, and the surface at a hit.
#ifndef VKRAY_PRIMITIVES_GLSL
#define VKRAY_PRIMITIVES_GLSL

#include "instances.glsl"
#include "intersect.glsl"
#include "resources.glsl"
#include "shared/sampling.h"
#include "texture.glsl"

// t of the nearest intersection with the primitive in (t_min, t_max), or -1.
float intersect_primitive(Ray ray, RayShear shear, vec4 a, vec4 b, vec4 c, float t_min, float t_max) {
  if (SCENE_HAS_SPHERES && (primitive_flags(a) & VKRAY_PRIM_SPHERE) != 0u)
    return intersect_sphere(ray, a.xyz, sphere_radius(b), t_min, t_max);
  return intersect_triangle(ray, shear, a.xyz, b.xyz, c.xyz, t_min, t_max);
}

// ---- Vertex colours (shared/scene_layout.h) ----------------------------------------------------------------
// The colour of the coloured triangle in slot `prim` at barycentrics b: its vertices' interpolated.
vec4 vertex_colour(uint prim, vec2 b) {
  int base = int(prim) * VKRAY_TEXELS_PER_PRIMITIVE;
  return (1.0 - b.x - b.y) * texelFetch(colours, base) + b.x * texelFetch(colours, base + 1) + b.y * texelFetch(colours, base + 2);
}

// ---- Alpha (shared/materials.h) ----------------------------------------------------------------------------
// The opacity of the primitive in slot `prim`, its flags `flags`, at barycentrics b (a triangle's; a
// sphere has no texture coordinates, and its material's factor is its opacity); `alpha`: its
// material's VKRAY_MATERIAL_OPACITY texel.
float opacity_at(uint prim, uint flags, vec2 b, out vec4 alpha) {
  int material = material_texel(primitive_material(flags));
  alpha = texelFetch(materials, material + VKRAY_MATERIAL_OPACITY);
  float opacity = alpha.x;
  if (SCENE_HAS_TEXTURES && (flags & VKRAY_PRIM_SPHERE) == 0u) {
    vec4 header = texelFetch(materials, material + VKRAY_MATERIAL_OPACITY_TEXTURE);
    if (has_texture(header)) opacity *= sample_texture_rgba(header, material + VKRAY_MATERIAL_OPACITY_TEXTURE, triangle_texcoord(prim, b)).a;
  }
  if (SCENE_HAS_VERTEX_COLOURS && (flags & VKRAY_PRIM_COLOURED) != 0u) opacity *= vertex_colour(prim, b).a;
  return opacity;
}

// Whether a ray with alpha key `key` (shared/sampling.h) that reaches the primitive of `hit` meets it
// there: always, but on a primitive of a see-through material, where its opacity decides (on a
// sphere, for the side the ray leaves by apart from the side it enters by). scene_index: the
// primitive's place in the scene, from the texel read here (and its instance's).
bool meets_hit(Ray world_ray, Hit hit, uint key, out uint scene_index) {
  bool placed = SCENE_HAS_INSTANCES && hit.instance != NO_INSTANCE;
  Ray ray = placed ? ray_to_mesh(hit.instance, world_ray) : world_ray;
  int base = int(hit.prim) * VKRAY_TEXELS_PER_PRIMITIVE;
  vec4 a = texelFetch(primitives, base), b = texelFetch(primitives, base + 1), c = texelFetch(primitives, base + 2);
  scene_index = primitive_scene_index(b) + (placed ? instance_header(hit.instance).first_index : 0u);
  uint flags = primitive_flags(a);
  if ((flags & VKRAY_PRIM_ALPHA) == 0u) return true;
  bool sphere = (flags & VKRAY_PRIM_SPHERE) != 0u;
  vec3 x = ray_at(ray, hit.t);
  vec2 bary = sphere ? vec2(0.0) : triangle_hit_barycentrics(ray, a.xyz, b.xyz, c.xyz);
  vec4 alpha;
  float opacity = opacity_at(hit.prim, flags, bary, alpha);
  bool far_side = sphere && dot(ray.dir, x - a.xyz) > 0.0;
  return alpha_solid(alpha_mode_of(alpha), opacity, alpha.y, alpha_random(key, scene_index, far_side));
}

// ---- Normal maps ---------------------------------------------------------------------------------------
// The unit shading normal n of the triangle in primitive slot `prim`, at barycentrics b, turned by a
// tangent-space normal map's value `texel`, its red and green scaled by `scale` (glTF's formula),
// in MikkTSpace's frame: the interpolated tangent t, not normalized, and the bitangent
// sign cross(n, t). n itself where the triangle has no tangents or the result has no length.
vec3 normal_mapped(vec3 n, uint prim, vec2 b, vec3 texel, float scale) {
  int base = int(prim) * VKRAY_TEXELS_PER_PRIMITIVE;
  vec4 t0 = texelFetch(tangents, base), t1 = texelFetch(tangents, base + 1), t2 = texelFetch(tangents, base + 2);
  float b0 = 1.0 - b.x - b.y;
  vec3 t = b0 * t0.xyz + b.x * t1.xyz + b.y * t2.xyz;
  float sign = b0 * t0.w + b.x * t1.w + b.y * t2.w;
  vec3 bt = (sign < 0.0 ? -1.0 : 1.0) * cross(n, t);
  vec3 m = (2.0 * texel - 1.0) * vec3(scale, scale, 1.0);
  vec3 perturbed = m.x * t + m.y * bt + m.z * n;
  float length2 = dot(perturbed, perturbed);
  return t0.w != 0.0 && length2 > 0.0 ? perturbed * inversesqrt(length2) : n;
}

// ---- The surface at a hit -------------------------------------------------------------------------------
struct Surface {
  vec3 geometric_normal;  // unit, not yet oriented toward the ray: the side it faces emits
  vec3 shading_normal;    // unit: the geometric normal, or the interpolated vertex normal; then the normal map's
  vec3 albedo;            // the material's colour (shared/materials.h), its texture applied
  uint material_type;     // VKRAY_MATERIAL_*: only bsdf.glsl asks it
  uint properties;        // VKRAY_BSDF_*: what everything else asks
  vec3 emission;          // its texture applied
  float ior;
  vec3 eta;               // a conductor's complex index of refraction
  vec3 k;
  vec2 alpha;             // GGX roughness along the frame's two tangents
  float metallic;         // metallic_roughness
  float roughness;
  float transmission;     // metallic_roughness
  float light_pdf_area;   // the density per unit area with which light sampling picks this point (emitters.glsl)
  bool emits_both_sides;  // its emission leaves both sides, not only the geometric normal's
};

// The surface where `ray` hits: `hit`, with the ray in the space of the hit primitive's own texels.
Surface local_surface(Hit hit, Ray ray) {
  vec3 position = ray_at(ray, hit.t);
  int base = int(hit.prim) * VKRAY_TEXELS_PER_PRIMITIVE;
  vec4 a = texelFetch(primitives, base);
  uint flags = primitive_flags(a);
  int material = material_texel(primitive_material(flags));
  // The material's value texels: each fetched only where the scene has a material that uses it.
  MaterialValueTexels t;
  t.color = texelFetch(materials, material + VKRAY_MATERIAL_COLOR);
  t.emission = vec4(0.0, 0.0, 0.0, 1.0);
  t.eta = vec4(0.0);
  t.k = vec4(0.0);
  t.layers = vec4(0.0);
  uint properties = material_properties_of(t.color);
  vec4 light = vec4(0.0);
  if (SCENE_HAS_EMITTERS || SCENE_HAS_NON_DIFFUSE) {
    t.emission = texelFetch(materials, material + VKRAY_MATERIAL_EMISSION);
    light = texelFetch(materials, material + VKRAY_MATERIAL_LIGHT);
  }
  if (SCENE_HAS_NON_DIFFUSE && (properties & VKRAY_BSDF_GLOSSY) != 0u) {
    t.eta = texelFetch(materials, material + VKRAY_MATERIAL_ETA);
    t.k = texelFetch(materials, material + VKRAY_MATERIAL_K);
    t.layers = texelFetch(materials, material + VKRAY_MATERIAL_LAYERS);
  }
  MaterialValues m = material_values(t);
  Surface s;
  s.albedo = m.color;
  s.material_type = m.type;
  s.properties = properties;
  s.emission = m.emission;
  s.ior = m.ior;
  s.eta = m.eta;
  s.k = m.k;
  s.alpha = vec2(m.alpha_u, m.alpha_v);
  s.metallic = m.metallic;
  s.roughness = m.roughness;
  s.transmission = m.transmission;
  s.light_pdf_area = light.x;
  s.emits_both_sides = light.y != 0.0;
  if (SCENE_HAS_SPHERES && (flags & VKRAY_PRIM_SPHERE) != 0u) {
    s.geometric_normal = (position - a.xyz) / sphere_radius(texelFetch(primitives, base + 1));
    if ((flags & VKRAY_PRIM_INWARD) != 0u) s.geometric_normal = -s.geometric_normal;
    s.shading_normal = s.geometric_normal;
    return s;
  }
  vec3 v1 = texelFetch(primitives, base + 1).xyz, v2 = texelFetch(primitives, base + 2).xyz;
  s.geometric_normal = triangle_normal(a.xyz, v1, v2);
  s.shading_normal = s.geometric_normal;
  bool smooth_normals = (flags & VKRAY_PRIM_SMOOTH) != 0u;
  vec4 albedo_texture = vec4(0.0), emission_texture = vec4(0.0), layers_texture = vec4(0.0), normal_texture = vec4(0.0),
       transmission_texture = vec4(0.0);
  if (SCENE_HAS_TEXTURES) {
    albedo_texture = texelFetch(materials, material + VKRAY_MATERIAL_ALBEDO_TEXTURE);
    emission_texture = texelFetch(materials, material + VKRAY_MATERIAL_EMISSION_TEXTURE);
    if (SCENE_HAS_metallic_roughness) {
      layers_texture = texelFetch(materials, material + VKRAY_MATERIAL_LAYERS_TEXTURE);
      transmission_texture = texelFetch(materials, material + VKRAY_MATERIAL_TRANSMISSION_TEXTURE);
    }
    if (SCENE_HAS_NORMAL_MAPS) normal_texture = texelFetch(materials, material + VKRAY_MATERIAL_NORMAL_TEXTURE);
  }
  bool textured = SCENE_HAS_TEXTURES && (has_texture(albedo_texture) || has_texture(emission_texture) || has_texture(layers_texture) ||
                                         has_texture(normal_texture) || has_texture(transmission_texture));
  bool coloured = SCENE_HAS_VERTEX_COLOURS && (flags & VKRAY_PRIM_COLOURED) != 0u;
  if (!smooth_normals && !textured && !coloured) return s;
  vec2 b = triangle_hit_barycentrics(ray, a.xyz, v1, v2);
  if (coloured) {  // glTF's COLOR_0: it multiplies the base colour, which an unlit material emits
    vec3 colour = vertex_colour(hit.prim, b).rgb;
    if (vertex_colours_emit_of(texelFetch(materials, material + VKRAY_MATERIAL_OPACITY)))
      s.emission *= colour;
    else
      s.albedo *= colour;
  }
  if (smooth_normals)
    s.shading_normal = normalize((1.0 - b.x - b.y) * texelFetch(normals, base).xyz + b.x * texelFetch(normals, base + 1).xyz +
                                 b.y * texelFetch(normals, base + 2).xyz);
  if (textured) {
    TexCoords uv = triangle_texcoord(hit.prim, b);
    if (has_texture(albedo_texture)) s.albedo *= sample_texture(albedo_texture, material + VKRAY_MATERIAL_ALBEDO_TEXTURE, uv);
    if (has_texture(emission_texture)) s.emission *= sample_texture(emission_texture, material + VKRAY_MATERIAL_EMISSION_TEXTURE, uv);
    if (has_texture(layers_texture)) {  // glTF's metallicRoughnessTexture: metalness in blue, roughness in green
      vec3 layers = sample_texture(layers_texture, material + VKRAY_MATERIAL_LAYERS_TEXTURE, uv);
      s.metallic *= layers.b;
      s.roughness *= layers.g;
    }
    if (has_texture(transmission_texture))  // glTF's transmissionTexture: transmission in red
      s.transmission *= sample_texture(transmission_texture, material + VKRAY_MATERIAL_TRANSMISSION_TEXTURE, uv).r;
    if (SCENE_HAS_NORMAL_MAPS && has_texture(normal_texture))
      s.shading_normal = normal_mapped(s.shading_normal, hit.prim, b, sample_texture(normal_texture, material + VKRAY_MATERIAL_NORMAL_TEXTURE, uv),
                                       texelFetch(materials, material + VKRAY_MATERIAL_LAYERS).z);
  }
  return s;
}

// The surface where `ray` hits: `hit`. In an instance, its mesh's surface found with the ray in the
// mesh's space, its normals turned to world space.
Surface hit_surface(Hit hit, Ray ray) {
  bool placed = SCENE_HAS_INSTANCES && hit.instance != NO_INSTANCE;
  Surface s = local_surface(hit, placed ? ray_to_mesh(hit.instance, ray) : ray);
  if (placed) {
    s.geometric_normal = normal_to_world(hit.instance, s.geometric_normal);
    s.shading_normal = normal_to_world(hit.instance, s.shading_normal);
  }
  return s;
}

#endif
