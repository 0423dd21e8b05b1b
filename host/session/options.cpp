#include "session/options.h"

#include "base/errors.h"

namespace vkray {
namespace {

uint32_t in_range(const std::optional<uint32_t>& value, uint32_t fallback, uint32_t max, const char* what) {
  if (!value) return fallback;
  if (*value < 1 || *value > max)
    throw UsageError(std::string(what) + " " + std::to_string(*value) + " is out of range (1 to " + std::to_string(max) + ")");
  return *value;
}

}  // namespace

ImageSettings image_settings(const Scene& scene, const RenderOptions& options) {
  return {in_range(options.width, scene.image.width, kMaxImageSide, "width"),
          in_range(options.height, scene.image.height, kMaxImageSide, "height"),
          in_range(options.samples_per_pixel, scene.image.samples_per_pixel, kMaxSamplesPerPixel, "samples per pixel"),
          options.seed.value_or(scene.image.seed)};
}

}  // namespace vkray
