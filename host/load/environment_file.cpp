#include "load/environment_file.h"

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "base/errors.h"
#include "base/extension.h"
#include "image/exr.h"
#include "image/hdr_read.h"

namespace vkray {

std::shared_ptr<const Image> read_environment_map(const std::filesystem::path& file, float scale, float* brightest) {
  const std::string extension = lower_extension(file);
  if (extension != ".hdr" && extension != ".exr")
    throw SceneError(file.string() + ": an environment map is a Radiance .hdr or an OpenEXR .exr file");
  auto map = std::make_shared<Image>();
  try {
    *map = extension == ".hdr" ? read_hdr(file) : read_exr(file).image;
  } catch (const LimitError&) {
    throw;
  } catch (const InputError& e) {
    throw SceneError(e.what());
  }
  if (map->width != 2 * map->height)
    throw SceneError(file.string() + ": an equirectangular map is twice as wide as it is high; this one is " +
                     std::to_string(map->width) + " x " + std::to_string(map->height));
  // Scaled and checked on every core; the first bad texel in the map's order is the one named.
  std::atomic<size_t> first_bad{map->pixels.size()};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, map->pixels.size(), 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const glm::vec3 scaled = map->pixels[i] * scale;
      if (!(scaled.r >= 0.0f && scaled.g >= 0.0f && scaled.b >= 0.0f && scaled.r <= FLT_MAX && scaled.g <= FLT_MAX && scaled.b <= FLT_MAX)) {
        for (size_t seen = first_bad.load(); i < seen && !first_bad.compare_exchange_weak(seen, i);) {
        }
        return;
      }
    }
  });
  if (first_bad < map->pixels.size()) {
    const size_t i = first_bad;
    const glm::vec3 texel = map->pixels[i], scaled = texel * scale;
    int c = 0;
    while (c < 2 && std::isfinite(scaled[c]) && scaled[c] >= 0.0f) ++c;
    std::ostringstream what;
    what << file.string() << ": texel (" << i % map->width << ", " << i / map->width << ") (column, row from the top) is " << texel[c]
         << " in its " << "RGB"[c] << " channel";
    if (std::isfinite(texel[c]) && texel[c] >= 0.0f) what << ", " << scaled[c] << " at the scale " << scale;
    what << ": an environment's radiance is finite and not negative";
    throw SceneError(what.str());
  }
  const float most = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, map->pixels.size(), 1 << 16), 0.0f,
      [&](const tbb::blocked_range<size_t>& r, float m) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          glm::vec3& p = map->pixels[i];
          if (scale != 1.0f) p *= scale;
          m = std::max({m, p.r, p.g, p.b});
        }
        return m;
      },
      [](float a, float b) { return std::max(a, b); });
  if (brightest) *brightest = most;
  return map;
}

void set_environment(Scene& scene, const std::filesystem::path& file) {
  Environment environment;
  environment.file = file;
  environment.radiance = read_environment_map(file, 1.0f, &environment.brightest);
  scene.environment = std::move(environment);
  scene.background = glm::vec3(0.0f);
  scene.referenced_files.push_back(file);
}

}  // namespace vkray
