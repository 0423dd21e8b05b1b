// The area lights: one picked from the alias table (shared/scene_layout.h) by its power, and a
// point on it picked uniformly by area. Its density per unit area is then the same for every
// light of a material, emission luminance over the table's total power, computed on the host in
// double (VKRAY_MATERIAL_LIGHT), which is what lets a hit on an emitter know how likely light
// sampling was to find it (multiple importance sampling).
#ifndef VKRAY_EMITTERS_GLSL
#define VKRAY_EMITTERS_GLSL

#include "instances.glsl"
#include "intersect.glsl"
#include "primitives.glsl"
#include "resources.glsl"
#include "shared/sampling.h"
#include "texture.glsl"
#include "warp.glsl"

struct LightPoint {
  vec3 position;
  vec3 normal;     // unit, the side that emits (with both_sides, the other too)
  bool both_sides;
  vec3 radiance;   // emitted toward that side
  float pdf_area;  // density of picking this point, per unit area
};

// Draws three numbers from the stream: the light, then the point on it.
LightPoint sample_area_light(inout uint stream) {
  float u_pick = next_random(stream);
  vec2 u = vec2(next_random(stream), next_random(stream));
  uint entry = alias_entry(u_pick, frame.emitter_count);
  vec4 texel = texelFetch(emitters, int(entry) * VKRAY_TEXELS_PER_EMITTER);
  uint chosen = alias_keeps_entry(u_pick, frame.emitter_count, entry, texel.x) ? entry : floatBitsToUint(texel.y);
  vec4 light_texel = texelFetch(emitters, int(chosen) * VKRAY_TEXELS_PER_EMITTER);
  uint prim = floatBitsToUint(light_texel.z);
  uint entry_plus_one = floatBitsToUint(light_texel.w);  // its instance's entry + 1; 0: none

  int base = int(prim) * VKRAY_TEXELS_PER_PRIMITIVE;
  vec4 a = texelFetch(primitives, base), b = texelFetch(primitives, base + 1), c = texelFetch(primitives, base + 2);
  uint flags = primitive_flags(a);
  LightPoint light;
  vec3 w = vec3(0.0);
  if (SCENE_HAS_SPHERES && (flags & VKRAY_PRIM_SPHERE) != 0u) {
    vec3 d = uniform_sphere(u);
    light.position = a.xyz + sphere_radius(b) * d;
    light.normal = (flags & VKRAY_PRIM_INWARD) != 0u ? -d : d;
  } else {
    w = uniform_triangle(u);
    light.position = w.x * a.xyz + w.y * b.xyz + w.z * c.xyz;
    light.normal = triangle_normal(a.xyz, b.xyz, c.xyz);
    // In an instance, a point uniform on the mesh's triangle is uniform on the placed one too (an
    // affine map scales every area of a triangle alike); its normal turns by the inverse transpose.
    if (SCENE_HAS_INSTANCES && entry_plus_one != 0u) {
      light.position = point_to_world(entry_plus_one - 1u, light.position);
      light.normal = normal_to_world(entry_plus_one - 1u, light.normal);
    }
  }
  vec4 emission = texelFetch(materials, material_texel(primitive_material(flags)) + VKRAY_MATERIAL_EMISSION);
  vec4 density = texelFetch(materials, material_texel(primitive_material(flags)) + VKRAY_MATERIAL_LIGHT);
  // The light is picked by its material's emission; a texture only scales what the point sends.
  light.pdf_area = density.x;
  light.both_sides = density.y != 0.0;
  light.radiance = emission.rgb;
  if (SCENE_HAS_TEXTURES) {
    int slot = material_texel(primitive_material(flags)) + VKRAY_MATERIAL_EMISSION_TEXTURE;
    vec4 emission_texture = texelFetch(materials, slot);
    bool sphere = SCENE_HAS_SPHERES && (flags & VKRAY_PRIM_SPHERE) != 0u;  // spheres have no texture coordinates
    if (!sphere && has_texture(emission_texture)) light.radiance *= sample_texture(emission_texture, slot, triangle_texcoord(prim, w.yz));
  }
  // An unlit emitter's vertex colours are part of its base colour, which it emits.
  if (SCENE_HAS_VERTEX_COLOURS && (flags & VKRAY_PRIM_COLOURED) != 0u &&
      vertex_colours_emit_of(texelFetch(materials, material_texel(primitive_material(flags)) + VKRAY_MATERIAL_OPACITY)))
    light.radiance *= vertex_colour(prim, w.yz).rgb;
  // Of a see-through emitter, only the part that is there sends light (shared/materials.h, alpha_coverage).
  if (SCENE_HAS_ALPHA && (flags & VKRAY_PRIM_ALPHA) != 0u) {
    vec4 alpha;
    float opacity = opacity_at(prim, flags, w.yz, alpha);
    light.radiance *= alpha_coverage(alpha_mode_of(alpha), opacity, alpha.y);
  }
  return light;
}

#endif
