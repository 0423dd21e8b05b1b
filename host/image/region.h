// A rectangle of an image's pixels, in the full image's coordinates: what `vkray render --region`
// renders and what a part file holds. Half-open, as pbrt's crop windows and EXR data windows (made
// inclusive) are: x0 <= x < x1, y0 <= y < y1.
#pragma once

#include <cstdint>
#include <string>

namespace vkray {

struct PixelRegion {
  uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;

  uint32_t width() const { return x1 - x0; }
  uint32_t height() const { return y1 - y0; }
  uint64_t pixels() const { return uint64_t(width()) * height(); }
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool overlaps(const PixelRegion& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool within(uint32_t image_width, uint32_t image_height) const {
    return !empty() && x1 <= image_width && y1 <= image_height;
  }
  bool operator==(const PixelRegion&) const = default;
};

inline PixelRegion full_region(uint32_t width, uint32_t height) { return {0, 0, width, height}; }

// "X0,Y0,X1,Y1", as --region takes it.
inline std::string to_string(const PixelRegion& r) {
  return std::to_string(r.x0) + "," + std::to_string(r.y0) + "," + std::to_string(r.x1) + "," + std::to_string(r.y1);
}

}  // namespace vkray
