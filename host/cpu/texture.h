// Texture lookups for the CPU reference: bilinear or nearest with glTF's wrap modes, in double,
// written apart from shaders/texture.glsl.
#pragma once

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray::cpu {

// The colour and alpha of `ref`'s texture at texture coordinate uv ((0, 0) the top left corner of the picture).
glm::dvec4 sample_texture_rgba(const Scene& scene, const TextureRef& ref, const glm::dvec2& uv);
// The texture coordinate `ref` reads (its set) on triangle t at barycentrics (u, v).
inline glm::dvec2 triangle_texcoord(const Triangle& t, const TextureRef& ref, double u, double v) {
  const std::array<glm::vec2, 3>& c = t.texcoords(ref.texcoord);
  return (1 - u - v) * glm::dvec2(c[0]) + u * glm::dvec2(c[1]) + v * glm::dvec2(c[2]);
}
// Its colour.
inline glm::dvec3 sample_texture(const Scene& scene, const TextureRef& ref, const glm::dvec2& uv) {
  return glm::dvec3(sample_texture_rgba(scene, ref, uv));
}

}  // namespace vkray::cpu
