#include "session/options.h"

#include <algorithm>

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

std::string ArgumentLimit::problem(std::string_view text) const {
  const bool negative = text.starts_with('-');
  const std::string_view digits = text.substr(negative ? 1 : 0);
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos)
    return "expected a decimal integer, got \"" + printable(text) + "\"";
  const std::string_view significant = digits.substr(std::min(digits.find_first_not_of('0'), digits.size() - 1));
  if (negative) return expected(text);                               // below every limit
  if (significant.size() > 10) return expected(significant);         // past every limit, and an int64_t
  return contains(std::stoll(std::string(significant))) ? "" : expected(significant);
}

uint32_t ArgumentLimit::read(std::string_view text) const {
  if (const std::string why = problem(text); !why.empty()) throw UsageError(std::string(name) + ": " + why);
  const std::string_view digits = text.substr(std::min(text.find_first_not_of('0'), text.size() - 1));
  return uint32_t(std::stoull(std::string(digits)));
}

ImageSettings image_settings(const Scene& scene, const RenderOptions& options) {
  if (options.threads != 0 && !kThreadsArgument.contains(options.threads))
    throw kThreadsArgument.error(std::to_string(options.threads));
  if (!kTileTimeoutArgument.contains(options.tile_timeout.count()))
    throw kTileTimeoutArgument.error(std::to_string(options.tile_timeout.count()));
  if (!options.sample_environment && scene.integrator.type != Integrator::Type::path)
    throw UsageError("environment_sampling: \"bsdf\" is for the path integrator; the direct model samples no BSDF at a diffuse "
                     "surface, so only sampling the map lights it");
  return {checked(options.width, scene.image.width, kWidthArgument), checked(options.height, scene.image.height, kHeightArgument),
          checked(options.samples_per_pixel, scene.image.samples_per_pixel, kSppArgument),
          checked(options.seed, scene.image.seed, kSeedArgument)};
}

}  // namespace vkray
