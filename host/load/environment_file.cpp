#include "load/environment_file.h"

#include <cmath>
#include <sstream>

#include "base/errors.h"
#include "base/extension.h"
#include "image/exr.h"
#include "image/hdr_read.h"

namespace vkray {

std::shared_ptr<const Image> read_environment_map(const std::filesystem::path& file, float scale) {
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
  for (size_t i = 0; i < map->pixels.size(); ++i) {
    glm::vec3& texel = map->pixels[i];
    const glm::vec3 scaled = texel * scale;
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(scaled[c]) && scaled[c] >= 0.0f) continue;
      std::ostringstream what;
      what << file.string() << ": texel (" << i % map->width << ", " << i / map->width << ") (column, row from the top) is "
           << texel[c] << " in its " << "RGB"[c] << " channel";
      if (std::isfinite(texel[c]) && texel[c] >= 0.0f) what << ", " << scaled[c] << " at the scale " << scale;
      what << ": an environment's radiance is finite and not negative";
      throw SceneError(what.str());
    }
    texel = scaled;
  }
  return map;
}

void set_environment(Scene& scene, const std::filesystem::path& file) {
  Environment environment;
  environment.file = file;
  environment.radiance = read_environment_map(file, 1.0f);
  scene.environment = std::move(environment);
  scene.background = glm::vec3(0.0f);
  scene.referenced_files.push_back(file);
}

}  // namespace vkray
