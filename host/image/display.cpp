#include "image/display.h"

#include <algorithm>
#include <cmath>

#include "image/image.h"

namespace vkray {
namespace {

// Stephen Hill's fit of ACES (github.com/TheRealMJP/BakingLab, ACES.hlsl): sRGB to the RRT's input
// space, the RRT and the sRGB ODT as one rational curve, and back to sRGB. Matrices row by row.
glm::vec3 aces(glm::vec3 c) {
  const glm::vec3 v(0.59719f * c.r + 0.35458f * c.g + 0.04823f * c.b,  //
                    0.07600f * c.r + 0.90834f * c.g + 0.01566f * c.b,  //
                    0.02840f * c.r + 0.13383f * c.g + 0.83777f * c.b);
  const glm::vec3 a = v * (v + 0.0245786f) - 0.000090537f;
  const glm::vec3 b = v * (0.983729f * v + 0.4329510f) + 0.238081f;
  const glm::vec3 f = a / b;
  return glm::vec3(1.60475f * f.r - 0.53108f * f.g - 0.07367f * f.b,  //
                   -0.10208f * f.r + 1.10813f * f.g - 0.00605f * f.b,  //
                   -0.00327f * f.r - 0.07276f * f.g + 1.07602f * f.b);
}

// The Khronos PBR Neutral tone mapper, as its reference (KhronosGroup/ToneMapping, pbrNeutral.glsl):
// colours below 0.76 pass unchanged but for a small offset in the darks; brighter ones are
// compressed towards 1 and desaturated towards white as they go.
glm::vec3 pbr_neutral(glm::vec3 color) {
  constexpr float kStartCompression = 0.8f - 0.04f;
  constexpr float kDesaturation = 0.15f;
  const float x = std::min(color.r, std::min(color.g, color.b));
  const float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
  color -= offset;
  const float peak = std::max(color.r, std::max(color.g, color.b));
  if (peak < kStartCompression) return color;
  constexpr float d = 1.0f - kStartCompression;
  const float new_peak = 1.0f - d * d / (peak + d - kStartCompression);
  color *= new_peak / peak;
  const float g = 1.0f - 1.0f / (kDesaturation * (peak - new_peak) + 1.0f);
  return glm::mix(color, glm::vec3(new_peak), g);
}

}  // namespace

std::string_view tonemap_name(Tonemap tonemap) {
  switch (tonemap) {
    case Tonemap::none: return "none";
    case Tonemap::aces: return "aces";
    case Tonemap::pbr_neutral: return "pbr-neutral";
  }
  return "none";
}

std::optional<Tonemap> parse_tonemap(std::string_view name) {
  for (Tonemap t : {Tonemap::none, Tonemap::aces, Tonemap::pbr_neutral})
    if (tonemap_name(t) == name) return t;
  return std::nullopt;
}

std::string tonemap_names() { return "none, aces or pbr-neutral"; }

float DisplayTransform::scale() const { return std::exp2(exposure); }

glm::vec3 DisplayTransform::apply(glm::vec3 radiance) const {
  glm::vec3 c = exposure == 0.0f ? radiance : radiance * scale();
  // NaN and negatives: nothing to show (the tone mappers take c >= 0); infinity, and anything past
  // where every tone mapper is white, as 1e18, which their arithmetic carries without overflow.
  for (int i = 0; i < 3; ++i) c[i] = c[i] >= 0.0f ? std::min(c[i], 1e18f) : 0.0f;
  switch (tonemap) {
    case Tonemap::none: break;
    case Tonemap::aces: c = aces(c); break;
    case Tonemap::pbr_neutral: c = pbr_neutral(c); break;
  }
  return glm::clamp(c, 0.0f, 1.0f);
}

void DisplayTransform::encode(glm::vec3 radiance, uint8_t out[3]) const {
  if (is_identity()) {  // exactly what a PNG always held, byte for byte
    for (int i = 0; i < 3; ++i) out[i] = encode_srgb8(radiance[i]);
    return;
  }
  const glm::vec3 c = apply(radiance);
  for (int i = 0; i < 3; ++i) out[i] = encode_srgb8(c[i]);
}

}  // namespace vkray
