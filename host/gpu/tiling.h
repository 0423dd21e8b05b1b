// How a render's image is cut into submissions: rectangles taken in order from the top, and how
// many pixels the next one gets, from the time the last ones took, so that a fast GPU gets a few
// large submissions and a CPU driver many short ones. Pixels never depend on any of it (each pixel's
// samples depend only on its position in the image): only the time does.
#pragma once

#include <cstdint>

namespace vkray::gpu {

struct TileRect {
  uint32_t x0 = 0, y0 = 0, width = 0, height = 0;
  uint64_t pixels() const { return uint64_t(width) * height; }
};

// Cuts a width x height image into rectangles, in bands of whole rows from the top. A band's rows are
// a multiple of `granule` (the workgroup's side), but for the last; a band narrower than the image
// is cut across into pieces `granule` wide or a multiple of it, left to right.
class TileCursor {
 public:
  TileCursor(uint32_t width, uint32_t height, uint32_t granule);

  bool done() const { return y_ >= height_; }
  // The next rectangle, of at most `pixels` pixels where one granule-high band piece allows it (and
  // never less than granule x granule, or what is left): whole rows while `pixels` holds a
  // granule's rows of the image.
  TileRect next(uint64_t pixels);
  // The next side x side square (cut short at the image's edges), in bands `side` rows high.
  TileRect next_square(uint32_t side);

 private:
  TileRect take(uint32_t band_rows, uint32_t piece_width);

  uint32_t width_, height_, granule_;
  uint32_t x_ = 0, y_ = 0, band_rows_ = 0;
};

// The pixels of the next submission. Each finished submission gives a rate (pixels a second), and
// the next one is sized to last about `target_seconds` at that rate; it grows at most 8x and
// shrinks at most 4x from the last measured one, and stays within [least, most] (most, an output
// slot's size, wins where least is larger).
class SubmissionSizer {
 public:
  SubmissionSizer(uint64_t first, uint64_t least, uint64_t most, double target_seconds);

  uint64_t next() const { return next_; }
  // A submission of `pixels` pixels took `seconds` of device time.
  void finished(uint64_t pixels, double seconds);

 private:
  uint64_t least_, most_, next_ = 0;
  double target_seconds_;
};

}  // namespace vkray::gpu
