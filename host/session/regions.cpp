#include "session/regions.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include "base/errors.h"
#include "cpu/reference.h"

namespace vkray {
namespace {

// The probe's rows: enough to see where the sky ends and a model begins, few enough that the probe
// takes a small fraction of any render it splits.
constexpr uint32_t kProbeRows = 128;
constexpr uint32_t kProbeMaxColumns = 256;

const char* const kRegionForms = "expected X0,Y0,X1,Y1 (pixel bounds, x0 < x1, y0 < y1) or I/N (band I of N, 0 <= I < N)";

// The decimal numbers in `text` separated by `separator`; false when it is anything else.
bool parse_numbers(std::string_view text, char separator, std::vector<uint32_t>& numbers) {
  while (true) {
    const size_t end = std::min(text.find(separator), text.size());
    const std::string_view digits = text.substr(0, end);
    uint32_t value = 0;
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos) return false;
    const auto [ptr, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error != std::errc() || ptr != digits.data() + digits.size()) return false;
    numbers.push_back(value);
    if (end == text.size()) return true;
    text.remove_prefix(end + 1);
  }
}

}  // namespace

RegionRequest parse_region(std::string_view text) {
  const std::string quoted = "region \"" + printable(text) + "\": ";
  std::vector<uint32_t> n;
  if (text.find('/') != std::string_view::npos) {
    if (!parse_numbers(text, '/', n) || n.size() != 2) throw UsageError(quoted + kRegionForms);
    if (n[1] == 0 || n[0] >= n[1])
      throw UsageError(quoted + "band " + std::to_string(n[0]) + " of " + std::to_string(n[1]) +
                       " does not exist: bands count from 0, so 0 <= I < N");
    return Band{n[0], n[1]};
  }
  if (!parse_numbers(text, ',', n) || n.size() != 4) throw UsageError(quoted + kRegionForms);
  const PixelRegion region{n[0], n[1], n[2], n[3]};
  if (region.empty()) throw UsageError(quoted + "an empty rectangle: " + kRegionForms);
  return region;
}

std::vector<PixelRegion> work_bands(const Scene& scene, const ImageSettings& image, uint32_t count, const SceneBvh* bvh) {
  if (count == 0 || count > image.height)
    throw UsageError(std::to_string(count) + " bands of a " + std::to_string(image.height) +
                     "-row image: a band has at least one row, so 1 to " + std::to_string(image.height));
  if (count == 1) return {full_region(image.width, image.height)};

  // ---- the probe: a small render of the same view, its rays counted row by row ----
  ImageSettings probe = image;
  probe.height = std::min(image.height, kProbeRows);
  // The same aspect, so that the probe sees what the image sees (the camera's focal length is in
  // units of the image height).
  probe.width = uint32_t(std::clamp(std::lround(double(image.width) * probe.height / image.height), 1l, long(kProbeMaxColumns)));
  probe.samples_per_pixel = 1;
  // A fixed seed: the bands of a render must not change with its seed (a path's length is random),
  // so that `--region I/N` names the same pixels for every seed, and frames of one view share them.
  probe.seed = 0;
  cpu::ReferenceOptions options;
  options.bvh = bvh;
  // One thread: the probe is small, and the rays it counts do not depend on threads anyway.
  options.threads = 1;
  const cpu::ReferenceResult result = cpu::render_reference(scene, probe, options);

  // ---- rows of the image weighted by the probe row they fall in; bands at equal shares ----
  std::vector<double> before(image.height + 1, 0.0);  // before[y]: the cost of rows 0 to y - 1
  for (uint32_t y = 0; y < image.height; ++y) {
    const uint32_t probe_row = uint32_t(uint64_t(y) * probe.height / image.height);
    // Rays per image pixel of that probe row (a miss still costs its camera ray).
    const double cost = double(std::max<uint64_t>(result.rays_per_row[probe_row], probe.width)) / probe.width;
    before[y + 1] = before[y] + cost;
  }
  std::vector<PixelRegion> bands;
  bands.reserve(count);
  uint32_t start = 0;
  for (uint32_t i = 1; i <= count; ++i) {
    uint32_t end = image.height;
    if (i < count) {
      // The row boundary nearest to an i/count share of the cost, keeping a row for this band and
      // one for each band after it.
      const double target = before[image.height] * i / count;
      end = uint32_t(std::lower_bound(before.begin(), before.end(), target) - before.begin());
      if (end > 0 && target - before[end - 1] < before[end] - target) --end;
      end = std::clamp(end, start + 1, image.height - (count - i));
    }
    bands.push_back({0, start, image.width, end});
    start = end;
  }
  return bands;
}

PixelRegion resolve_region(const Scene& scene, const ImageSettings& image, const RegionRequest& request, const SceneBvh* bvh) {
  if (const Band* band = std::get_if<Band>(&request)) return work_bands(scene, image, band->count, bvh)[band->index];
  const PixelRegion region = std::get<PixelRegion>(request);
  if (!region.within(image.width, image.height))
    throw UsageError("region " + to_string(region) + " does not lie within the " + std::to_string(image.width) + " x " +
                     std::to_string(image.height) + " image (x1 <= width, y1 <= height)");
  return region;
}

}  // namespace vkray
