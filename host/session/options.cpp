#include "session/options.h"

#include "base/errors.h"

namespace vkray {
namespace {

uint32_t checked(const std::optional<uint32_t>& value, uint32_t fallback, const ArgumentLimit& limit) {
  if (!value) return fallback;
  if (!limit.contains(*value)) throw limit.error(std::to_string(*value));
  return *value;
}

}  // namespace

std::string ArgumentLimit::expected(std::string_view got) const {
  return "expected an integer from " + std::to_string(min) + " to " + std::to_string(max) + ", got " + printable(got);
}

UsageError ArgumentLimit::error(std::string_view got) const { return UsageError(std::string(name) + ": " + expected(got)); }

ImageSettings image_settings(const Scene& scene, const RenderOptions& options) {
  if (options.threads != 0 && !kThreadsArgument.contains(options.threads))
    throw kThreadsArgument.error(std::to_string(options.threads));
  if (!kTileTimeoutArgument.contains(options.tile_timeout.count()))
    throw kTileTimeoutArgument.error(std::to_string(options.tile_timeout.count()));
  return {checked(options.width, scene.image.width, kWidthArgument), checked(options.height, scene.image.height, kHeightArgument),
          checked(options.samples_per_pixel, scene.image.samples_per_pixel, kSppArgument),
          checked(options.seed, scene.image.seed, kSeedArgument)};
}

}  // namespace vkray
