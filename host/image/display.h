// How linear radiance becomes an 8-bit display value: an exposure in stops, a tone mapper, then
// the sRGB encoding of image.h. Used for PNG files and for `vkray view`'s window; EXR and PFM files
// stay linear radiance.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

namespace vkray {

enum class Tonemap {
  none,         // clamp to [0, 1]: the shading contract's encoding (a PNG as vkray always wrote it)
  aces,         // ACES filmic, Stephen Hill's fit of the RRT and sRGB ODT (as Khronos' glTF Sample Viewer)
  pbr_neutral,  // the Khronos PBR Neutral tone mapper (KhronosGroup/ToneMapping)
};

// "none", "aces", "pbr-neutral": the names the command line and Python take.
std::string_view tonemap_name(Tonemap tonemap);
std::optional<Tonemap> parse_tonemap(std::string_view name);
// "none, aces or pbr-neutral", for messages.
std::string tonemap_names();

struct DisplayTransform {
  Tonemap tonemap = Tonemap::none;
  float exposure = 0.0f;  // in stops: radiance is scaled by 2^exposure before the tone mapper

  bool is_identity() const { return tonemap == Tonemap::none && exposure == 0.0f; }
  // The scale the exposure gives (1 at 0 stops, exactly).
  float scale() const;
  // Linear radiance to display-linear values in [0, 1] (the sRGB encoding comes after). NaN is 0.
  glm::vec3 apply(glm::vec3 radiance) const;
  // The 8-bit sRGB values of a pixel, as a PNG stores them.
  void encode(glm::vec3 radiance, uint8_t out[3]) const;
};

// The largest exposure either way, in stops: past it every pixel is black or white.
constexpr float kMaxExposure = 64.0f;

}  // namespace vkray
