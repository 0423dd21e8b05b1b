// Texture lookups (layout in shared/scene_layout.h): bilinear or nearest, with glTF's wrap modes
// (OpenGL's rules: texel centres at half-integer coordinates, (0, 0) the picture's top left corner).
// host/cpu/texture.cpp does the same for the CPU reference, written again.
#ifndef VKRAY_TEXTURE_GLSL
#define VKRAY_TEXTURE_GLSL

#include "resources.glsl"

// A coordinate reduced to one period of its wrap mode, exactly (u - 2 floor(u / 2) rounds nothing),
// so that texel indices stay small whatever the coordinate.
float reduce_coordinate(float u, uint wrap) {
  if (wrap == VKRAY_WRAP_CLAMP_TO_EDGE) return clamp(u, 0.0, 1.0);
  if (wrap == VKRAY_WRAP_MIRRORED_REPEAT) return u - 2.0 * floor(u * 0.5);
  return u - floor(u);
}

// Texel index i (from -1 to two periods) wrapped into [0, size).
int wrap_texel(int i, int size, uint wrap) {
  if (wrap == VKRAY_WRAP_CLAMP_TO_EDGE) return clamp(i, 0, size - 1);
  if (wrap == VKRAY_WRAP_MIRRORED_REPEAT) {
    int period = 2 * size;
    int m = (i + period) % period;
    return m < size ? m : period - 1 - m;
  }
  return (i + size) % size;
}

vec4 texture_fetch(TextureHeader t, int x, int y) { return texelFetch(textures, int(t.first + uint(y) * t.width + uint(x))); }

// A primitive's two texture coordinate sets at a point: a texture reads the one its header names.
struct TexCoords {
  vec2 first;
  vec2 second;
};

// The texture of the material's texture slot whose first texel (the header, texture_texel) is
// header_texel, at index `slot` in the materials buffer, at the primitive's texture coordinates:
// the set the header names, mapped by the slot's transform first where the header says it has one.
// Colour and alpha.
vec4 sample_texture_rgba(vec4 header_texel, int slot, TexCoords coords) {
  TextureHeader t = texture_header(header_texel);
  vec2 uv = texture_texcoord_set(t.mode) == 0u ? coords.first : coords.second;
  if (texture_transformed(t.mode)) {
    vec3 p = vec3(uv, 1.0);
    uv = vec2(dot(texelFetch(materials, slot + 1).xyz, p), dot(texelFetch(materials, slot + 2).xyz, p));
  }
  uint wrap_s = texture_wrap_s(t.mode), wrap_t = texture_wrap_t(t.mode);
  int width = int(t.width), height = int(t.height);
  float x = reduce_coordinate(uv.x, wrap_s) * float(width), y = reduce_coordinate(uv.y, wrap_t) * float(height);
  if (texture_filter(t.mode) == VKRAY_FILTER_NEAREST)
    return texture_fetch(t, wrap_texel(int(floor(x)), width, wrap_s), wrap_texel(int(floor(y)), height, wrap_t));
  // Bilinear: the four texels whose centres surround (x, y), weighed by distance.
  x -= 0.5;
  y -= 0.5;
  float x0 = floor(x), y0 = floor(y);
  float ax = x - x0, ay = y - y0;
  int i0 = wrap_texel(int(x0), width, wrap_s), i1 = wrap_texel(int(x0) + 1, width, wrap_s);
  int j0 = wrap_texel(int(y0), height, wrap_t), j1 = wrap_texel(int(y0) + 1, height, wrap_t);
  vec4 top = (1.0 - ax) * texture_fetch(t, i0, j0) + ax * texture_fetch(t, i1, j0);
  vec4 bottom = (1.0 - ax) * texture_fetch(t, i0, j1) + ax * texture_fetch(t, i1, j1);
  return (1.0 - ay) * top + ay * bottom;
}

// The same, colour only.
vec3 sample_texture(vec4 header_texel, int slot, TexCoords coords) { return sample_texture_rgba(header_texel, slot, coords).rgb; }

// Whether a material texel names a texture (its width is not 0).
bool has_texture(vec4 header_texel) { return floatBitsToUint(header_texel.y) != 0u; }

// The two texture coordinate sets at barycentrics (b1, b2) of the triangle in primitive slot `prim`.
TexCoords triangle_texcoord(uint prim, vec2 b) {
  int base = int(prim) * VKRAY_TEXELS_PER_TEXCOORDS;
  vec4 t0 = texelFetch(texcoords, base), t1 = texelFetch(texcoords, base + 1), t2 = texelFetch(texcoords, base + 2);
  float b0 = 1.0 - b.x - b.y;
  TexCoords c;
  c.first = b0 * t0.xy + b.x * t0.zw + b.y * t1.xy;
  c.second = b0 * t1.zw + b.x * t2.xy + b.y * t2.zw;
  return c;
}

#endif
