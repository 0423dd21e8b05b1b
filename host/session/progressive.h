// A render that a viewer advances frame by frame: each call traces one step (a band of rows, or
// samples of the whole image) sized to last about the time the caller can spare, at the rate
// measured so far. The image so far is each pixel's mean of the samples it has; once every pixel
// has all of the render's samples it is, bit for bit, the image Session::render returns for the same
// scene and options (gpu/accumulator.h).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "image/aovs.h"
#include "image/image.h"
#include "scene/scene.h"

namespace vkray {
namespace gpu {
class Accumulator;
}

class ProgressiveRender {
 public:
  ~ProgressiveRender();
  ProgressiveRender(const ProgressiveRender&) = delete;
  ProgressiveRender& operator=(const ProgressiveRender&) = delete;

  const ImageSettings& settings() const { return settings_; }
  uint32_t target() const { return settings_.samples_per_pixel; }
  // Samples every pixel has; rows [0, rows_ahead()) have one more.
  uint32_t samples() const { return samples_; }
  uint32_t rows_ahead() const { return rows_ahead_; }
  bool done() const { return samples_ == target(); }

  // Traces one step sized to last about `budget` at the rate measured so far (at least a band of
  // 8 rows, or what is left of the image). Returns false, having done nothing, once done(). Throws
  // what Session::render throws (TimeoutError past the options' tile timeout, Cancelled, ...).
  bool advance(std::chrono::duration<double> budget);

  // The image so far into `image` (settings' width x height): each pixel's mean of its samples.
  // Rows without a sample yet are left as they were.
  void image(Image& image) const;
  // With RenderOptions::aovs: the first-hit passes so far into `aovs` (settings' size), each the mean
  // over the samples that hit something; once done(), Session::render's. Rows without a sample yet
  // are left as they were.
  bool has_aovs() const;
  void aovs(Aovs& aovs) const;

  // Pixels x samples a second, as the last steps ran (0 before the first).
  double rate() const { return rate_; }
  // Device time and rays (camera + shadow) of all steps so far.
  double trace_seconds() const { return trace_seconds_; }
  uint64_t rays() const;

 private:
  friend class Session;
  ProgressiveRender(std::unique_ptr<gpu::Accumulator> accumulator, const ImageSettings& settings,
                    std::chrono::milliseconds timeout, double rate_hint);

  std::unique_ptr<gpu::Accumulator> accumulator_;
  ImageSettings settings_;
  std::chrono::milliseconds timeout_;
  uint32_t samples_ = 0, rows_ahead_ = 0;
  double rate_ = 0, trace_seconds_ = 0;
  mutable Image sums_;  // read back from the device for image()
};

}  // namespace vkray
