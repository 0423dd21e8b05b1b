#include "image/decode.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include <png.h>
#include <turbojpeg.h>

#include "base/errors.h"

namespace vkray {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& why) { throw SceneError(name + ": " + why); }

// Refuses a size past the limits before the pixels are allocated.
void check_size(const std::string& name, uint64_t width, uint64_t height) {
  if (width == 0 || height == 0) fail(name, "the picture has no pixels (" + std::to_string(width) + " x " + std::to_string(height) + ")");
  if (width > kMaxPictureSide || height > kMaxPictureSide || width * height > kMaxPicturePixels)
    throw LimitError(name + ": a picture of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels; vkray decodes at most " + std::to_string(kMaxPictureSide) + " on a side and " +
                     std::to_string(kMaxPicturePixels >> 20) + "M pixels (docs/limits.md)");
}

// libpng's simplified API: it converts any bit depth, palette and gamma to 8-bit sRGB RGBA, and
// reports errors in the struct instead of by longjmp.
class PngReader {
 public:
  PngReader(std::string_view bytes, const std::string& name) {
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    // A constructor that throws runs no destructor: the struct is freed here on every failure.
    if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) {
      const std::string message = image.message;
      png_image_free(&image);
      fail(name, "not a readable PNG file: " + message);
    }
    try {
      check_size(name, image.width, image.height);
    } catch (...) {
      png_image_free(&image);
      throw;
    }
  }
  ~PngReader() { png_image_free(&image); }
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;
  png_image image;
};

// TurboJPEG's decompressor, with the header read and checked.
class JpegReader {
 public:
  JpegReader(std::string_view bytes, const std::string& name)
      : handle(tjInitDecompress(), tjDestroy), data(reinterpret_cast<const unsigned char*>(bytes.data())),
        size(static_cast<unsigned long>(bytes.size())) {
    if (!handle) throw LimitError(name + ": TurboJPEG could not start: " + tjGetErrorStr2(nullptr));
    int subsampling = 0, colorspace = 0;
    if (tjDecompressHeader3(handle.get(), data, size, &width, &height, &subsampling, &colorspace) != 0)
      fail(name, std::string("not a readable JPEG file: ") + tjGetErrorStr2(handle.get()));
    if (colorspace == TJCS_CMYK || colorspace == TJCS_YCCK) fail(name, "a CMYK JPEG file; textures must be RGB or greyscale");
    check_size(name, uint64_t(std::max(width, 0)), uint64_t(std::max(height, 0)));
  }
  std::unique_ptr<void, int (*)(tjhandle)> handle;
  const unsigned char* data;
  unsigned long size;
  int width = 0, height = 0;
};

Picture decode_png(std::string_view bytes, const std::string& name) {
  PngReader reader(bytes, name);
  png_image& image = reader.image;
  image.format = PNG_FORMAT_RGBA;
  Picture picture{image.width, image.height, std::vector<uint8_t>(PNG_IMAGE_SIZE(image))};
  if (!png_image_finish_read(&image, nullptr, picture.rgba.data(), 0, nullptr))
    fail(name, std::string("a damaged PNG file: ") + image.message);
  return picture;
}

Picture decode_jpeg(std::string_view bytes, const std::string& name) {
  JpegReader reader(bytes, name);
  const int width = reader.width, height = reader.height;
  Picture picture{uint32_t(width), uint32_t(height), std::vector<uint8_t>(size_t(width) * size_t(height) * 4)};
  // TJFLAG_LIMITSCANS: a progressive file of thousands of tiny scans is refused, not decoded for minutes.
  if (tjDecompress2(reader.handle.get(), reader.data, reader.size, picture.rgba.data(), width, 0, height, TJPF_RGBA,
                    TJFLAG_ACCURATEDCT | TJFLAG_LIMITSCANS) != 0)
    fail(name, std::string("a damaged JPEG file: ") + tjGetErrorStr2(reader.handle.get()));
  return picture;
}

}  // namespace

bool is_png(std::string_view bytes) { return bytes.size() >= 8 && bytes.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8); }
bool is_jpeg(std::string_view bytes) { return bytes.size() >= 3 && bytes.substr(0, 3) == std::string_view("\xff\xd8\xff", 3); }

PictureSize picture_size(std::string_view bytes, const std::string& name) {
  if (is_png(bytes)) {
    const PngReader reader(bytes, name);
    return {reader.image.width, reader.image.height};
  }
  if (is_jpeg(bytes)) {
    const JpegReader reader(bytes, name);
    return {uint32_t(reader.width), uint32_t(reader.height)};
  }
  fail(name, bytes.empty() ? "the picture is empty" : "not a PNG or JPEG file (vkray's textures are PNG or JPEG)");
}

Picture decode_picture(std::string_view bytes, const std::string& name) {
  if (is_png(bytes)) return decode_png(bytes, name);
  if (is_jpeg(bytes)) return decode_jpeg(bytes, name);
  fail(name, bytes.empty() ? "the picture is empty" : "not a PNG or JPEG file (vkray's textures are PNG or JPEG)");
}

}  // namespace vkray
