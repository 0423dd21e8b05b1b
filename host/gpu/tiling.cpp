#include "gpu/tiling.h"

#include <algorithm>
#include <cmath>

namespace vkray::gpu {

TileCursor::TileCursor(uint32_t width, uint32_t height, uint32_t granule)
    : width_(width), height_(height), granule_(std::max(granule, 1u)) {}

TileRect TileCursor::take(uint32_t band_rows, uint32_t piece_width) {
  if (x_ == 0) band_rows_ = std::min(band_rows, height_ - y_);  // a new band
  TileRect rect{x_, y_, std::min(piece_width, width_ - x_), band_rows_};
  x_ += rect.width;
  if (x_ >= width_) {
    x_ = 0;
    y_ += band_rows_;
  }
  return rect;
}

TileRect TileCursor::next(uint64_t pixels) {
  const auto multiple_of_granule = [&](uint64_t n) {
    return uint32_t(std::clamp<uint64_t>(n / granule_ * granule_, granule_, UINT32_MAX / 2));
  };
  const uint32_t band_rows = x_ == 0 ? multiple_of_granule(pixels / width_) : band_rows_;
  const uint32_t rows = std::min(band_rows, height_ - y_);
  return take(band_rows, multiple_of_granule(pixels / rows));
}

TileRect TileCursor::next_square(uint32_t side) { return take(side, side); }

SubmissionSizer::SubmissionSizer(uint64_t first, uint64_t least, uint64_t most, double target_seconds)
    : least_(std::min(least, most)), most_(most), target_seconds_(target_seconds) {  // `most` is the slot: it wins
  next_ = std::clamp(first, least_, most_);
}

void SubmissionSizer::finished(uint64_t pixels, double seconds) {
  const double pixels_at_rate = seconds > 0 ? double(pixels) / seconds * target_seconds_ : double(pixels) * 8.0;
  const double bounded = std::clamp(pixels_at_rate, double(pixels) / 4.0, double(pixels) * 8.0);
  next_ = std::clamp(uint64_t(bounded), least_, most_);
}

}  // namespace vkray::gpu
