// The first-hit passes (AOVs, "arbitrary output variables") a render returns beside its image, for
// denoisers, compositing and analysis: what each pixel's camera rays hit first. Both renderers fill
// them by one rule, Mitsuba's `aov` integrator's: albedo, normal, position and depth are the means
// over the pixel's samples that hit something (depth is infinite where none did); `object` is the
// object the pixel's first sample hit, -1 where it hit nothing.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace vkray {

enum class Aov : uint32_t {
  albedo,    // the surface's reflectance: a diffuse albedo, a mirror's reflectance, 1 for glass
  normal,    // the shading normal, world space, on the side the surface faces (not turned to the ray)
  position,  // the hit point, world space
  depth,     // the camera ray's length to the hit
  object,    // the index of the object hit in the scene file's "objects"
};
constexpr std::array<Aov, 5> kAllAovs{Aov::albedo, Aov::normal, Aov::position, Aov::depth, Aov::object};

const char* aov_name(Aov aov);
// "albedo,depth" (names from aov_name, comma-separated, each at most once) to the passes, in the
// order given. Throws UsageError naming an unknown or repeated name.
std::vector<Aov> parse_aov_list(std::string_view text);

// What one pixel's samples saw first, summed: the one place the rule above is applied.
struct FirstHitSums {
  glm::dvec3 albedo{0.0}, normal{0.0}, position{0.0};
  double depth = 0;
  uint32_t hits = 0;
  int32_t object = -1;
};

struct Aovs {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec3> albedo, normal, position;  // row-major, top row first, as Image
  std::vector<float> depth;
  std::vector<int32_t> object;

  Aovs() = default;
  Aovs(uint32_t w, uint32_t h);
  // Stores the means of `sums` for pixel (x, y).
  void set(uint32_t x, uint32_t y, const FirstHitSums& sums);
  size_t pixels() const { return size_t(width) * height; }
};

}  // namespace vkray
