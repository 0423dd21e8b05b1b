#include "image/hdr_read.h"

#include <cstdlib>
#include <memory>
#include <new>
#include <string>
#include <vector>

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
namespace {

// Whether the pixel data after the header holds the `width` x `height` pixels stb_image will read,
// walked as stb_image walks it: flat RGBE quadruples, or per scanline the run-length form (2, 2, the
// width in two bytes, then each of the four channels as runs and literal spans). stb_image reads
// past the end of its buffer as zeros and takes a span of length 0 for no progress, so a file cut
// short in a run-length scanline would never finish decoding, and one cut short in flat pixels
// would decode what is not there: both are refused here first. Returns what is wrong, or "".
std::string scanline_problem(const unsigned char* data, size_t size, uint32_t width, uint32_t height) {
  size_t at = 0;
  const auto flat_rows = [&](uint32_t rows) -> std::string {
    const uint64_t need = uint64_t(rows) * width * 4;
    return size - at < need ? "the file ends before its last pixel" : "";
  };
  if (width < 8 || width >= 32768) return flat_rows(height);
  for (uint32_t y = 0; y < height; ++y) {
    if (size - at < 4) return "the file ends before its last scanline";
    if (data[at] != 2 || data[at + 1] != 2 || (data[at + 2] & 0x80)) return flat_rows(height - y);  // flat from here on
    at += 4;
    for (int channel = 0; channel < 4; ++channel) {
      for (uint32_t x = 0; x < width;) {
        if (at >= size) return "the file ends within scanline " + std::to_string(y);
        uint32_t count = data[at++];
        const bool run = count > 128;
        if (run) count -= 128;
        if (count == 0 || count > width - x) return "scanline " + std::to_string(y) + " has a run of length " + std::to_string(count);
        const size_t bytes = run ? 1 : count;
        if (size - at < bytes) return "the file ends within scanline " + std::to_string(y);
        at += bytes;
        x += count;
      }
    }
  }
  return "";
}

// Where the pixels start: after the header's blank line and the resolution line.
size_t pixels_offset(const std::string& text) {
  const size_t blank = text.find("\n\n");
  if (blank == std::string::npos) return std::string::npos;
  const size_t resolution_end = text.find('\n', blank + 2);
  return resolution_end == std::string::npos ? std::string::npos : resolution_end + 1;
}

}  // namespace

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
  const size_t offset = pixels_offset(input.text);
  const std::string problem = offset == std::string::npos
                                  ? "no resolution line after its header"
                                  : scanline_problem(bytes + offset, input.text.size() - offset, uint32_t(width), uint32_t(height));
  if (!problem.empty()) throw InputError(file.string() + ": unreadable Radiance pixels (" + problem + ")");
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
