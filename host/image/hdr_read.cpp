#include "image/hdr_read.h"

#include <cstdlib>
#include <memory>
#include <new>
#include <string>

#include "base/errors.h"
#include "base/input_file.h"

// stb_image's own code, compiled here for Radiance files alone (vkray reads PNG and JPEG through
// libpng and libjpeg-turbo).
#define STBI_ONLY_HDR
#define STBI_NO_STDIO
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace vkray {

Image read_hdr(const std::filesystem::path& file) {
  const InputFile input = read_input_file(file, kMaxPictureFileBytes);
  if (!input.error.empty()) throw InputError(file.string() + ": " + input.error);
  const auto* bytes = reinterpret_cast<const stbi_uc*>(input.text.data());
  const int length = static_cast<int>(input.text.size());  // at most kMaxPictureFileBytes, 1 GiB
  if (!stbi_is_hdr_from_memory(bytes, length))
    throw InputError(file.string() + ": not a Radiance .hdr file (it does not start with \"#?RADIANCE\" or \"#?RGBE\")");
  int width = 0, height = 0, channels = 0;
  if (!stbi_info_from_memory(bytes, length, &width, &height, &channels))
    throw InputError(file.string() + ": unreadable Radiance header (" + stbi_failure_reason() + ")");
  if (width < 1 || height < 1 || uint32_t(width) > kMaxImageSide || uint32_t(height) > kMaxImageSide)
    throw InputError(file.string() + ": " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels; vkray reads at most " + std::to_string(kMaxImageSide) + " on a side");
  Image image;
  try {
    image = Image(uint32_t(width), uint32_t(height));
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(file, uint32_t(width), uint32_t(height));
  }
  const std::unique_ptr<float, decltype(&stbi_image_free)> pixels(stbi_loadf_from_memory(bytes, length, &width, &height, &channels, 3),
                                                                   &stbi_image_free);
  if (!pixels) throw InputError(file.string() + ": unreadable Radiance pixels (" + stbi_failure_reason() + ")");
  const float* p = pixels.get();
  for (glm::vec3& texel : image.pixels) {
    texel = glm::vec3(p[0], p[1], p[2]);
    p += 3;
  }
  return image;
}

}  // namespace vkray
