#include "session/parts.h"

#include <cmath>

#include "base/errors.h"
#include "scene/digest.h"
#include "session/version.h"
#include "image/image_file.h"

namespace vkray {

PartRecord part_record(const Scene& scene, const RenderResult& result, const std::string& device) {
  PartRecord record;
  record.scene_digest = scene_digest(scene);
  record.width = result.settings.width;
  record.height = result.settings.height;
  record.region = result.region;
  record.samples_per_pixel = result.settings.samples_per_pixel;
  record.seed = result.settings.seed;
  record.version = version_string();
  record.device = device;
  record.shader = result.shader;
  return record;
}

void check_part_file(const std::filesystem::path& file) {
  if (!is_exr(file) && !is_pfm(file))
    throw UsageError(file.string() + ": a region of a render is written as a part for `vkray merge`: name the output "
                                     "*.exr or *.pfm");
}

void check_render_output(const std::filesystem::path& file, const OutputContent& content, bool part) {
  check_output_image(file);
  check_render_image(file, content);
  if (part) check_part_file(file);
}

void check_finite(const RenderResult& result) {
  const Image& image = result.image;
  size_t count = 0, first = 0;
  for (size_t i = image.pixels.size(); i-- > 0;)
    if (!std::isfinite(image.pixels[i].r) || !std::isfinite(image.pixels[i].g) || !std::isfinite(image.pixels[i].b)) {
      ++count;
      first = i;
    }
  if (count == 0) return;
  const uint64_t x = first % image.width + result.region.x0, y = first / image.width + result.region.y0;
  throw InternalError(std::to_string(count) + " pixel" + (count == 1 ? " is" : "s are") + " not finite, the first at (" +
                      std::to_string(x) + ", " + std::to_string(y) +
                      "): a fault of the shaders or of the device's driver, not an image to write; `vkray parity` on "
                      "the scene compares the device with the CPU reference");
}

void write_render(const std::filesystem::path& file, const Scene& scene, const RenderResult& result, const OutputContent& content,
                  const std::string& device) {
  check_finite(result);
  const Aovs* aovs = result.aovs ? &*result.aovs : nullptr;
  if (!is_part(result)) return write_render_image(file, result.image, aovs, content);
  write_part(file, result.image, aovs, content, part_record(scene, result, device));
}

}  // namespace vkray
