#include "image/aovs.h"

#include <algorithm>
#include <limits>

#include "base/errors.h"

namespace vkray {

const char* aov_name(Aov aov) {
  switch (aov) {
    case Aov::albedo: return "albedo";
    case Aov::normal: return "normal";
    case Aov::position: return "position";
    case Aov::depth: return "depth";
    case Aov::object: return "object";
  }
  return "?";
}

std::vector<Aov> parse_aov_list(std::string_view text) {
  std::vector<Aov> aovs;
  std::string known;
  for (Aov aov : kAllAovs) known += std::string(known.empty() ? "" : ", ") + aov_name(aov);
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string_view name = text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    const auto found = std::find_if(kAllAovs.begin(), kAllAovs.end(), [&](Aov aov) { return name == aov_name(aov); });
    if (found == kAllAovs.end())
      throw UsageError("unknown pass \"" + printable(name) + "\" (the passes are " + known + ")");
    if (std::find(aovs.begin(), aovs.end(), *found) != aovs.end())
      throw UsageError("the pass \"" + std::string(name) + "\" is named twice");
    aovs.push_back(*found);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return aovs;
}

Aovs::Aovs(uint32_t w, uint32_t h)
    : width(w),
      height(h),
      albedo(pixels(), glm::vec3(0.0f)),
      normal(pixels(), glm::vec3(0.0f)),
      position(pixels(), glm::vec3(0.0f)),
      depth(pixels(), std::numeric_limits<float>::infinity()),
      object(pixels(), -1) {}

void Aovs::set(uint32_t x, uint32_t y, const FirstHitSums& sums) {
  const size_t i = size_t(y) * width + x;
  object[i] = sums.object;
  if (sums.hits == 0) {
    albedo[i] = normal[i] = position[i] = glm::vec3(0.0f);
    depth[i] = std::numeric_limits<float>::infinity();
    return;
  }
  const double inv = 1.0 / sums.hits;
  albedo[i] = glm::vec3(sums.albedo * inv);
  normal[i] = glm::vec3(sums.normal * inv);
  position[i] = glm::vec3(sums.position * inv);
  depth[i] = float(sums.depth * inv);
}

}  // namespace vkray
