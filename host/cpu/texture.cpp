#include "cpu/texture.h"

#include <algorithm>
#include <cmath>

namespace vkray::cpu {
namespace {

// Texel index i of a row or column `size` long, by the wrap mode (OpenGL's rules): clamped, repeated,
// or repeated with every other copy mirrored.
int64_t wrap(int64_t i, int64_t size, TextureWrap mode) {
  switch (mode) {
    case TextureWrap::clamp_to_edge:
      return std::clamp<int64_t>(i, 0, size - 1);
    case TextureWrap::mirrored_repeat: {
      const int64_t m = ((i % (2 * size)) + 2 * size) % (2 * size);
      return m < size ? m : 2 * size - 1 - m;
    }
    case TextureWrap::repeat:
      break;
  }
  return ((i % size) + size) % size;
}

// The coordinate in texels, within one period of the wrap mode (the texel indices then stay small).
double texel_coordinate(double u, int64_t size, TextureWrap mode) {
  switch (mode) {
    case TextureWrap::clamp_to_edge:
      u = std::clamp(u, 0.0, 1.0);
      break;
    case TextureWrap::mirrored_repeat:
      u -= 2 * std::floor(u / 2);
      break;
    case TextureWrap::repeat:
      u -= std::floor(u);
      break;
  }
  return u * double(size);
}

}  // namespace

glm::dvec4 sample_texture_rgba(const Scene& scene, const TextureRef& ref, const glm::dvec2& primitive_uv) {
  const Texture& t = *scene.textures[size_t(ref.texture)];
  const int64_t w = t.width, h = t.height;
  const glm::dvec2 uv = ref.map(primitive_uv);
  const double x = texel_coordinate(uv.x, w, ref.wrap_s), y = texel_coordinate(uv.y, h, ref.wrap_t);
  const auto at = [&](int64_t i, int64_t j) {
    return glm::dvec4(t.texel(uint32_t(wrap(i, w, ref.wrap_s)), uint32_t(wrap(j, h, ref.wrap_t))));
  };
  if (ref.filter == TextureFilter::nearest) return at(int64_t(std::floor(x)), int64_t(std::floor(y)));
  // Bilinear: the four texels whose centres (at half-integer coordinates) surround (x, y).
  const double x0 = std::floor(x - 0.5), y0 = std::floor(y - 0.5);
  const double ax = x - 0.5 - x0, ay = y - 0.5 - y0;
  const auto i = int64_t(x0), j = int64_t(y0);
  return (1 - ay) * ((1 - ax) * at(i, j) + ax * at(i + 1, j)) + ay * ((1 - ax) * at(i, j + 1) + ax * at(i + 1, j + 1));
}

}  // namespace vkray::cpu
