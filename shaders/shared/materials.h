// The materials in one place, for both sides: each type's number and its name in scene files, the
// properties that code outside the BSDFs asks of a material (never its type), and the texels that
// carry its values to the shader (packed by the host, unpacked by the shader, with the functions
// here). Adding a material is a row of VKRAY_MATERIAL_TYPES, its values below if it has new ones,
// its paired BSDF functions (shaders/bsdf.glsl, host/cpu/bsdf.cpp) and its scene-file keys
// (host/load/scene_parser.cpp): docs/developing.md, "Where a change goes".
#ifndef VKRAY_SHARED_MATERIALS_H
#define VKRAY_SHARED_MATERIALS_H

#include "glsl_cpp.h"

VKRAY_SHARED_BEGIN

// ---- Properties: what a BSDF is made of (as pbrt-v4's BxDFFlags) ---------------------------------------
// DIFFUSE       a Lambertian lobe
// GLOSSY        a lobe that is neither Lambertian nor a delta: light sampling asks its eval and pdf
// DELTA         delta lobes only: no light sampling there, and a light met after it counts whole
// TRANSMISSION  light passes to the other side, so the surface is lit from both; a dielectric tells
//               inside from outside by the geometric normal, a thin one (metallic_roughness) has none
// CLEAR         its albedo pass is 1, not its colour (clear glass)
#define VKRAY_BSDF_DIFFUSE 1u
#define VKRAY_BSDF_GLOSSY 2u
#define VKRAY_BSDF_DELTA 4u
#define VKRAY_BSDF_TRANSMISSION 8u
#define VKRAY_BSDF_CLEAR 16u

// ---- The types: X(number, name in scene files, properties) ---------------------------------------------
// The host's MaterialType (scene/scene.h) and the scene parser's names are made from this table. A
// material's properties are its type's, with those its values add (material_value_properties).
#define VKRAY_MATERIAL_DIFFUSE 0u
#define VKRAY_MATERIAL_MIRROR 1u
#define VKRAY_MATERIAL_GLASS 2u
#define VKRAY_MATERIAL_ROUGHCONDUCTOR 3u
#define VKRAY_MATERIAL_ROUGHDIELECTRIC 4u
#define VKRAY_MATERIAL_METALLIC_ROUGHNESS 5u
#define VKRAY_MATERIAL_TYPES(X)                                                                    \
  X(VKRAY_MATERIAL_DIFFUSE, diffuse, VKRAY_BSDF_DIFFUSE)                                           \
  X(VKRAY_MATERIAL_MIRROR, mirror, VKRAY_BSDF_DELTA)                                               \
  X(VKRAY_MATERIAL_GLASS, glass, VKRAY_BSDF_DELTA | VKRAY_BSDF_TRANSMISSION | VKRAY_BSDF_CLEAR) \
  X(VKRAY_MATERIAL_ROUGHCONDUCTOR, roughconductor, VKRAY_BSDF_GLOSSY)                             \
  X(VKRAY_MATERIAL_ROUGHDIELECTRIC, roughdielectric, VKRAY_BSDF_GLOSSY | VKRAY_BSDF_TRANSMISSION | VKRAY_BSDF_CLEAR) \
  X(VKRAY_MATERIAL_METALLIC_ROUGHNESS, metallic_roughness, VKRAY_BSDF_DIFFUSE | VKRAY_BSDF_GLOSSY)
#define VKRAY_MATERIAL_TYPE_COUNT 6u

VKRAY_INLINE uint material_properties(uint type) {
#define VKRAY_MATERIAL_PROPERTIES_OF(number, name, properties) \
  if (type == number) return properties;
  VKRAY_MATERIAL_TYPES(VKRAY_MATERIAL_PROPERTIES_OF)
#undef VKRAY_MATERIAL_PROPERTIES_OF
  return 0u;
}

// The properties of a material of type `type` whose transmission (metallic_roughness: glTF's
// KHR_materials_transmission factor; 0 for every other type) is `transmission`: its type's, and
// TRANSMISSION where a metallic_roughness transmits. As pbrt's BxDF flags, they follow the values
// where the type alone cannot tell.
VKRAY_INLINE uint material_value_properties(uint type, float transmission) {
  uint properties = material_properties(type);
  if (type == VKRAY_MATERIAL_METALLIC_ROUGHNESS && transmission > 0.0f) properties |= VKRAY_BSDF_TRANSMISSION;
  return properties;
}

// The smoothest GGX surface either renderer evaluates: at alpha 1e-4 the distribution's peak,
// 1 / (pi alpha^2) = 3e7, and the densities made from it stay far inside a float. A rough material's
// alpha is at least this (the scene parser refuses less; glTF's roughness 0 is taken as this).
#define VKRAY_MIN_GGX_ALPHA 1e-4f

// ---- Alpha: how much of a surface is there (glTF's alphaMode) ------------------------------------------
// A material's opacity is its factor times the alpha of its opacity texture (shared/scene_layout.h:
// glTF's base colour texture, an .mtl file's map_d). OPAQUE: every ray meets all of the surface;
// MASK: where the opacity is at least the cutoff, and nowhere else; BLEND: stochastically, each ray
// meets it with probability the opacity (shared/sampling.h, alpha_random). The same for every ray:
// camera, shadow, indirect, and so the first-hit passes. A triangle's vertex colours' alpha multiplies
// the opacity too. Only primitives that can let a ray through carry VKRAY_PRIM_ALPHA (vkray::Scene::
// see_through of the triangle: its material's alpha, or a blending or masking material's vertex
// colours), and only they read the mode.
#define VKRAY_ALPHA_OPAQUE 0u
#define VKRAY_ALPHA_MASK 1u
#define VKRAY_ALPHA_BLEND 2u

// Whether a ray meets the surface where its opacity is `opacity`; u: alpha_random's number.
VKRAY_INLINE bool alpha_solid(uint mode, float opacity, float cutoff, float u) {
  if (mode == VKRAY_ALPHA_MASK) return opacity >= cutoff;
  if (mode == VKRAY_ALPHA_BLEND) return u < opacity;
  return true;
}

// The fraction of the surface there where its opacity is `opacity`, the mean of alpha_solid over u:
// what scales the light a point picked on an emitter sends.
VKRAY_INLINE float alpha_coverage(uint mode, float opacity, float cutoff) {
  if (mode == VKRAY_ALPHA_MASK) return opacity >= cutoff ? 1.0f : 0.0f;
  if (mode == VKRAY_ALPHA_BLEND) return min(max(opacity, 0.0f), 1.0f);
  return 1.0f;
}

// ---- The values: what a BSDF is evaluated from, before textures -----------------------------------------
struct MaterialValues {
  vec3 color;      // diffuse: albedo; mirror: reflectance; roughconductor: specular_reflectance; dielectrics: 1;
                   // metallic_roughness: the base colour
  uint type;       // VKRAY_MATERIAL_*
  vec3 emission;   // radiance emitted on the side the geometric normal faces (the shader's: scaled)
  float ior;       // glass, roughdielectric: the index of refraction inside (outside: 1); metallic_roughness: its dielectric's
  vec3 eta;        // roughconductor: the real part of its index of refraction (0 with k = 1: F = 1)
  float alpha_u;   // rough materials: GGX roughness along the shading frame's first tangent
  vec3 k;          // roughconductor: the imaginary part (absorption)
  float alpha_v;   // along the second tangent
  float metallic;  // metallic_roughness: glTF's metallicFactor
  float roughness; // metallic_roughness: glTF's roughnessFactor (its GGX alpha is its square)
  float normal_scale; // glTF's normalTexture.scale: multiplies the normal map's tangent and bitangent parts
  float transmission; // metallic_roughness: glTF's transmissionFactor (thin-walled: KHR_materials_transmission
                      // without KHR_materials_volume); 0 for every other type
};

// ---- Texels: VKRAY_TEXELS_PER_MATERIAL RGBA32F each ---------------------------------------------------
//   VKRAY_MATERIAL_COLOR:             (colour, type | properties << 8 as uint bits)
//   VKRAY_MATERIAL_EMISSION:          (emitted radiance, ior)
//   VKRAY_MATERIAL_ETA:               (eta, alpha_u)          read only by GLOSSY materials
//   VKRAY_MATERIAL_K:                 (k, alpha_v)            read only by GLOSSY materials
//   VKRAY_MATERIAL_LAYERS:            (metallic, roughness, normal_scale, transmission)  read by GLOSSY
//                                     materials and normal-mapped ones
//   VKRAY_MATERIAL_LIGHT:             (density per unit area with which light sampling picks a point of
//                                     an emitter of this material, 1 where it emits from both sides, 0,
//                                     0): scene/emitters.h
//   VKRAY_MATERIAL_OPACITY:           (opacity factor, alpha cutoff, alpha mode as uint bits, 1 where vertex
//                                     colours multiply the emission rather than the colour): read only for
//                                     primitives with VKRAY_PRIM_ALPHA or VKRAY_PRIM_COLOURED (opacity_texel)
// and six texture slots of VKRAY_TEXELS_PER_TEXTURE_SLOT texels each: the texture's header
// (texture_texel in shared/scene_layout.h), then the two rows of the affine map from a primitive's
// texture coordinate to the texture's (glTF's KHR_texture_transform), read only where the header says
// the texture is transformed:
//   VKRAY_MATERIAL_ALBEDO_TEXTURE:    the texture that multiplies the colour
//   VKRAY_MATERIAL_EMISSION_TEXTURE:  the texture that multiplies the emission
//   VKRAY_MATERIAL_LAYERS_TEXTURE:    metallic_roughness: the texture whose blue multiplies metallic and
//                                     whose green multiplies roughness (glTF's metallicRoughnessTexture)
//   VKRAY_MATERIAL_NORMAL_TEXTURE:    the tangent-space normal map (glTF's normalTexture)
//   VKRAY_MATERIAL_OPACITY_TEXTURE:   the texture whose alpha multiplies the opacity
//   VKRAY_MATERIAL_TRANSMISSION_TEXTURE: metallic_roughness: the texture whose red multiplies the
//                                     transmission (glTF's transmissionTexture)
#define VKRAY_TEXELS_PER_MATERIAL 25
#define VKRAY_TEXELS_PER_TEXTURE_SLOT 3
#define VKRAY_MATERIAL_COLOR 0
#define VKRAY_MATERIAL_EMISSION 1
#define VKRAY_MATERIAL_ETA 2
#define VKRAY_MATERIAL_K 3
#define VKRAY_MATERIAL_LAYERS 4
#define VKRAY_MATERIAL_LIGHT 5
#define VKRAY_MATERIAL_ALBEDO_TEXTURE 6
#define VKRAY_MATERIAL_EMISSION_TEXTURE 9
#define VKRAY_MATERIAL_LAYERS_TEXTURE 12
#define VKRAY_MATERIAL_NORMAL_TEXTURE 15
#define VKRAY_MATERIAL_OPACITY 18
#define VKRAY_MATERIAL_OPACITY_TEXTURE 19
#define VKRAY_MATERIAL_TRANSMISSION_TEXTURE 22
#define VKRAY_MATERIAL_PROPERTY_SHIFT 8u

// The first texel of material `index`.
VKRAY_INLINE int material_texel(uint index) { return int(index) * VKRAY_TEXELS_PER_MATERIAL; }

// The value texels (COLOR to LAYERS) of a material; its properties come from its type and values
// (material_value_properties), never from the caller.
struct MaterialValueTexels {
  vec4 color;
  vec4 emission;
  vec4 eta;
  vec4 k;
  vec4 layers;
};

VKRAY_INLINE MaterialValueTexels material_value_texels(MaterialValues m) {
  MaterialValueTexels t;
  t.color = vec4(m.color, uintBitsToFloat(m.type | (material_value_properties(m.type, m.transmission) << VKRAY_MATERIAL_PROPERTY_SHIFT)));
  t.emission = vec4(m.emission, m.ior);
  t.eta = vec4(m.eta, m.alpha_u);
  t.k = vec4(m.k, m.alpha_v);
  t.layers = vec4(m.metallic, m.roughness, m.normal_scale, m.transmission);
  return t;
}

VKRAY_INLINE uint material_type_of(vec4 color_texel) { return floatBitsToUint(color_texel.w) & ((1u << VKRAY_MATERIAL_PROPERTY_SHIFT) - 1u); }
VKRAY_INLINE uint material_properties_of(vec4 color_texel) { return floatBitsToUint(color_texel.w) >> VKRAY_MATERIAL_PROPERTY_SHIFT; }

VKRAY_INLINE MaterialValues material_values(MaterialValueTexels t) {
  MaterialValues m;
  m.color = vec3(t.color.x, t.color.y, t.color.z);
  m.type = material_type_of(t.color);
  m.emission = vec3(t.emission.x, t.emission.y, t.emission.z);
  m.ior = t.emission.w;
  m.eta = vec3(t.eta.x, t.eta.y, t.eta.z);
  m.alpha_u = t.eta.w;
  m.k = vec3(t.k.x, t.k.y, t.k.z);
  m.alpha_v = t.k.w;
  m.metallic = t.layers.x;
  m.roughness = t.layers.y;
  m.normal_scale = t.layers.z;
  m.transmission = t.layers.w;
  return m;
}

// A material's alpha, and what vertex colours multiply, in its VKRAY_MATERIAL_OPACITY texel, and back.
VKRAY_INLINE vec4 opacity_texel(float opacity, float cutoff, uint mode, bool vertex_colours_emit) {
  return vec4(opacity, cutoff, uintBitsToFloat(mode), vertex_colours_emit ? 1.0f : 0.0f);
}
VKRAY_INLINE uint alpha_mode_of(vec4 opacity_texel) { return floatBitsToUint(opacity_texel.z); }
VKRAY_INLINE bool vertex_colours_emit_of(vec4 opacity_texel) { return opacity_texel.w != 0.0f; }

VKRAY_SHARED_END

#endif  // VKRAY_SHARED_MATERIALS_H
