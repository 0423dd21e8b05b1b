// Which pixels a render covers when it is one part of a larger one (`vkray render --region`, the
// farm): a rectangle given in pixels, or the I-th of N bands of whole rows that cost about the same
// to render. Each pixel's samples depend only on its place in the full image, so parts assemble
// into exactly the full render (image/merge.h).
#pragma once

#include <cstdint>
#include <string_view>
#include <variant>
#include <vector>

#include "image/region.h"
#include "scene/scene.h"

namespace vkray {
struct SceneBvh;

// The I-th of N bands, counted from 0 (0 <= index < count).
struct Band {
  uint32_t index = 0, count = 1;
  bool operator==(const Band&) const = default;
};
using RegionRequest = std::variant<PixelRegion, Band>;

// "X0,Y0,X1,Y1" (pixel bounds, half-open) or "I/N", as --region takes it; decimal integers only.
// Throws UsageError saying which form was expected.
RegionRequest parse_region(std::string_view text);

// The most bands an image is cut into: one row each at least.
constexpr uint32_t kMaxBands = kMaxImageSide;

// `count` bands of whole rows, top to bottom, that cover the image and cost about the same: the
// cost of each row is estimated from a small render by the CPU reference (at most 128 rows of about
// the image's aspect, one sample a pixel, the scene's integrator), counting the rays each row traced.
// The bands depend only on the scene and the image settings, so every process that asks computes
// the same ones. `bvh`: one built for the scene; null builds one. Throws UsageError when count is 0
// or exceeds the image's rows, Cancelled on an interrupt request.
std::vector<PixelRegion> work_bands(const Scene& scene, const ImageSettings& image, uint32_t count, const SceneBvh* bvh = nullptr);

// The pixels `request` names in an image of `image`'s size: a rectangle is checked to lie within
// it (UsageError otherwise), a band is work_bands(...)[index].
PixelRegion resolve_region(const Scene& scene, const ImageSettings& image, const RegionRequest& request,
                           const SceneBvh* bvh = nullptr);

}  // namespace vkray
