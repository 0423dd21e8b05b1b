#include "session/progressive.h"

#include <algorithm>
#include <cmath>

#include "gpu/accumulator.h"
#include "session/on_device.h"

namespace vkray {
namespace {

// Bands are whole rows of workgroups (VKRAY_WORKGROUP_Y is 8).
constexpr uint32_t kBandRows = 8;
// A measured rate may grow at most this much from one step to the next: the first step's time
// holds the driver's compile (lavapipe compiles at the first dispatch), and a step cheap by chance
// (rows of sky) would plan the next one far too large.
constexpr double kMostGrowth = 8.0;

}  // namespace

ProgressiveRender::ProgressiveRender(std::unique_ptr<gpu::Accumulator> accumulator, const ImageSettings& settings,
                                     std::chrono::milliseconds timeout, double rate_hint)
    : accumulator_(std::move(accumulator)), settings_(settings), timeout_(timeout), rate_(rate_hint),
      sums_(settings.width, settings.height) {}

ProgressiveRender::~ProgressiveRender() = default;

uint64_t ProgressiveRender::rays() const { return accumulator_->rays(); }

bool ProgressiveRender::advance(std::chrono::duration<double> budget) {
  if (done()) return false;
  const uint32_t width = settings_.width, height = settings_.height;
  const uint64_t pixels = uint64_t(width) * height;
  // What the budget holds at the rate so far; before any step, one band.
  const double affordable = rate_ > 0 ? rate_ * std::max(budget.count(), 0.0) : double(width) * kBandRows;
  gpu::AccumulationStep step;
  if (rows_ahead_ == 0 && affordable >= double(pixels)) {
    // Whole samples of the whole image.
    const double samples = std::floor(affordable / double(pixels));
    step = {0, height, samples_, samples_ + uint32_t(std::min<double>(samples, target() - samples_))};
  } else {
    // A band of the next sample, from the first row that lacks it.
    const double rows = std::floor(affordable / double(width) / kBandRows) * kBandRows;
    const uint32_t band = uint32_t(std::min<double>(std::max<double>(rows, kBandRows), height - rows_ahead_));
    step = {rows_ahead_, rows_ahead_ + band, samples_, samples_ + 1};
  }
  const double seconds = on_device([&] { return accumulator_->trace(step, timeout_); });
  trace_seconds_ += seconds;
  const double measured = double(step.pixel_samples(width)) / std::max(seconds, 1e-6);
  rate_ = rate_ > 0 ? std::min(measured, rate_ * kMostGrowth) : measured;
  if (step.y0 == 0 && step.y1 == height) {
    samples_ = step.sample_end;
  } else {
    rows_ahead_ = step.y1;
    if (rows_ahead_ == height) {
      rows_ahead_ = 0;
      ++samples_;
    }
  }
  return true;
}

void ProgressiveRender::image(Image& image) const {
  if (image.width != settings_.width || image.height != settings_.height) image = Image(settings_.width, settings_.height);
  const auto mean_of = [&](uint32_t y0, uint32_t y1, uint32_t samples) {
    if (y0 >= y1 || samples == 0) return;
    accumulator_->read(y0, y1, sums_);
    // The sums are each sample over the whole render's count: at that count they are the mean.
    const float scale = float(target()) / float(samples);
    for (size_t i = size_t(y0) * settings_.width; i < size_t(y1) * settings_.width; ++i)
      image.pixels[i] = samples == target() ? sums_.pixels[i] : sums_.pixels[i] * scale;
  };
  mean_of(0, rows_ahead_, samples_ + 1);
  mean_of(rows_ahead_, settings_.height, samples_);
}

bool ProgressiveRender::has_aovs() const { return accumulator_->has_aovs(); }

void ProgressiveRender::aovs(Aovs& aovs) const {
  if (aovs.width != settings_.width || aovs.height != settings_.height) aovs = Aovs(settings_.width, settings_.height);
  // Rows with at least one sample: those ahead of the band, and all of them after a whole sample.
  const uint32_t rows = samples_ > 0 ? settings_.height : rows_ahead_;
  if (rows > 0) accumulator_->read_aovs(0, rows, aovs);
}

}  // namespace vkray
