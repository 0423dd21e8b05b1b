#include "image/decode.h"

#include <algorithm>
#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <png.h>
#include <turbojpeg.h>

#include "base/errors.h"
#include "image/image.h"

namespace vkray {
namespace {

// What a picture is decoded for: a texture, a scene's input (SceneError, the picture limits above),
// or an image file (image.h's read_png: InputError, kMaxImageSide on a side, no other limit).
enum class Use { texture, image_file };

[[noreturn]] void fail(Use use, const std::string& name, const std::string& why) {
  if (use == Use::image_file) throw InputError(name + ": " + why);
  throw SceneError(name + ": " + why);
}

// Refuses a size past the limits before the pixels are allocated.
void check_size(Use use, const std::string& name, uint64_t width, uint64_t height) {
  if (width == 0 || height == 0)
    fail(use, name, "the picture has no pixels (" + std::to_string(width) + " x " + std::to_string(height) + ")");
  if (use == Use::image_file) {
    if (width > kMaxImageSide || height > kMaxImageSide)
      fail(use, name, "a PNG of " + std::to_string(width) + " x " + std::to_string(height) + " pixels (vkray reads up to " +
                          std::to_string(kMaxImageSide) + " on a side)");
    return;
  }
  if (width > kMaxPictureSide || height > kMaxPictureSide || width * height > kMaxPicturePixels)
    throw LimitError(name + ": a picture of " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels; vkray decodes at most " + std::to_string(kMaxPictureSide) + " on a side and " +
                     std::to_string(kMaxPicturePixels >> 20) + "M pixels (docs/limits.md)");
}

// libpng's full API. Its simplified API (png_image) would do colour management vkray must not:
// it takes a 16-bit file's samples as linear light unless told otherwise and re-encodes them as sRGB
// (a mid grey rendered more than twice as bright as in 8 bits), and it applies a gAMA chunk to 8-bit
// samples too. Here no gamma transform is asked for, and the colour-space chunks are not even read.
// The bytes come from memory (a texture's file, read whole) or from an open file as libpng asks for
// them (an image file, which may be far larger than a texture's).
//
// libpng reports errors by longjmp: the structs are freed by a member's destructor (which runs when
// the constructor throws, too), and the functions that call setjmp create no C++ object that a
// longjmp would skip.
class PngReader {
 public:
  PngReader(std::string_view bytes, const std::string& name, Use use) : use_(use), bytes_(bytes) { start(name); }
  PngReader(std::FILE* file, const std::string& name, Use use) : use_(use), file_(file) { start(name); }
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;

  // Whether the file has an alpha channel or a transparent colour (tRNS).
  bool has_alpha() const {
    return (png_get_color_type(png_.png, png_.info) & PNG_COLOR_MASK_ALPHA) != 0 || png_get_valid(png_.png, png_.info, PNG_INFO_tRNS) != 0;
  }

  // The pixels as RGBA at the file's depth (8 bits, or 16 in the host's byte order) into `out`,
  // which holds height rows of width * 4 samples.
  void read(void* out, const std::string& name) {
    const size_t row_bytes = size_t(width) * 4 * (bit_depth == 16 ? 2 : 1);
    std::vector<png_bytep> rows(height);
    for (size_t y = 0; y < height; ++y) rows[y] = static_cast<png_bytep>(out) + y * row_bytes;
    if (!read_pixels(rows.data(), row_bytes)) fail(use_, name, std::string("a damaged PNG file: ") + message_);
  }

  uint32_t width = 0, height = 0;
  int bit_depth = 0;

 private:
  void start(const std::string& name) {
    png_.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, this, on_error, on_warning);
    if (png_.png) png_.info = png_create_info_struct(png_.png);
    if (!png_.png || !png_.info) throw LimitError(name + ": libpng could not start (out of memory)");
    if (!read_header()) fail(use_, name, std::string("not a readable PNG file: ") + message_);
    width = png_get_image_width(png_.png, png_.info);
    height = png_get_image_height(png_.png, png_.info);
    bit_depth = png_get_bit_depth(png_.png, png_.info);
    check_size(use_, name, width, height);
  }

  static void on_error(png_structp png, png_const_charp text) {
    auto* self = static_cast<PngReader*>(png_get_error_ptr(png));
    std::snprintf(self->message_, sizeof self->message_, "%s", text);
    png_longjmp(png, 1);
  }
  // A damaged ancillary chunk (text, time) is dropped with a warning; vkray reads none of them.
  static void on_warning(png_structp, png_const_charp) {}
  static void on_read(png_structp png, png_bytep out, size_t length) {
    auto* self = static_cast<PngReader*>(png_get_io_ptr(png));
    if (self->file_) {
      if (std::fread(out, 1, length, self->file_) != length)
        png_error(png, std::ferror(self->file_) ? "the file could not be read" : "the file ends early");
      return;
    }
    if (length > self->bytes_.size() - self->at_) png_error(png, "the file ends early");
    std::memcpy(out, self->bytes_.data() + self->at_, length);
    self->at_ += length;
  }

  // The signature and the chunks before the pixels.
  bool read_header() {
    if (setjmp(png_jmpbuf(png_.png))) return false;
    png_set_read_fn(png_.png, this, on_read);
    static constexpr png_byte kColourSpaceChunks[] = "gAMA\0cHRM\0iCCP\0sRGB";
    png_set_keep_unknown_chunks(png_.png, PNG_HANDLE_CHUNK_NEVER, kColourSpaceChunks, 4);
    png_read_info(png_.png, png_.info);
    return true;
  }

  // Every colour type to RGBA at its own depth, then the rows (all passes of an interlaced file).
  bool read_pixels(png_bytep* rows, size_t row_bytes) {
    if (setjmp(png_jmpbuf(png_.png))) return false;
    const png_byte colour_type = png_get_color_type(png_.png, png_.info);
    png_set_expand(png_.png);  // a palette to RGB, 1 to 4 bits to 8, tRNS to alpha
    if (!(colour_type & PNG_COLOR_MASK_COLOR)) png_set_gray_to_rgb(png_.png);
    if (!(colour_type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(png_.png, png_.info, PNG_INFO_tRNS))
      png_set_add_alpha(png_.png, bit_depth == 16 ? 0xffff : 0xff, PNG_FILLER_AFTER);
    if (bit_depth == 16 && std::endian::native == std::endian::little) png_set_swap(png_.png);
    png_set_interlace_handling(png_.png);
    png_read_update_info(png_.png, png_.info);
    if (png_get_rowbytes(png_.png, png_.info) != row_bytes) png_error(png_.png, "unexpected row size after expansion");
    png_read_image(png_.png, rows);
    png_read_end(png_.png, nullptr);
    return true;
  }

  struct Structs {
    png_structp png = nullptr;
    png_infop info = nullptr;
    ~Structs() { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); }
  };

  Structs png_;  // freed also when the constructor throws
  Use use_;
  std::string_view bytes_;  // the file's bytes, or
  std::FILE* file_ = nullptr;  // the file
  size_t at_ = 0;
  char message_[200] = "";
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
      fail(Use::texture, name, std::string("not a readable JPEG file: ") + tjGetErrorStr2(handle.get()));
    if (colorspace == TJCS_CMYK || colorspace == TJCS_YCCK) fail(Use::texture, name, "a CMYK JPEG file; textures must be RGB or greyscale");
    check_size(Use::texture, name, uint64_t(std::max(width, 0)), uint64_t(std::max(height, 0)));
  }
  std::unique_ptr<void, int (*)(tjhandle)> handle;
  const unsigned char* data;
  unsigned long size;
  int width = 0, height = 0;
};

Picture decode_png(PngReader& reader, const std::string& name) {
  Picture picture{reader.width, reader.height, {}, {}, reader.has_alpha()};
  const size_t samples = size_t(reader.width) * reader.height * 4;
  if (reader.bit_depth == 16) {
    picture.rgba16.resize(samples);
    reader.read(picture.rgba16.data(), name);
  } else {
    picture.rgba.resize(samples);
    reader.read(picture.rgba.data(), name);
  }
  return picture;
}

Picture decode_jpeg(std::string_view bytes, const std::string& name) {
  JpegReader reader(bytes, name);
  const int width = reader.width, height = reader.height;
  Picture picture{uint32_t(width), uint32_t(height), std::vector<uint8_t>(size_t(width) * size_t(height) * 4), {}, false};
  // TJFLAG_LIMITSCANS: a progressive file of thousands of tiny scans is refused, not decoded for minutes.
  if (tjDecompress2(reader.handle.get(), reader.data, reader.size, picture.rgba.data(), width, 0, height, TJPF_RGBA,
                    TJFLAG_ACCURATEDCT | TJFLAG_LIMITSCANS) != 0)
    fail(Use::texture, name, std::string("a damaged JPEG file: ") + tjGetErrorStr2(reader.handle.get()));
  return picture;
}

}  // namespace

bool is_png(std::string_view bytes) { return bytes.size() >= 8 && bytes.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8); }
bool is_jpeg(std::string_view bytes) { return bytes.size() >= 3 && bytes.substr(0, 3) == std::string_view("\xff\xd8\xff", 3); }

PictureSize picture_size(std::string_view bytes, const std::string& name) {
  if (is_png(bytes)) {
    const PngReader reader(bytes, name, Use::texture);
    return {reader.width, reader.height};
  }
  if (is_jpeg(bytes)) {
    const JpegReader reader(bytes, name);
    return {uint32_t(reader.width), uint32_t(reader.height)};
  }
  fail(Use::texture, name, bytes.empty() ? "the picture is empty" : "not a PNG or JPEG file (vkray's textures are PNG or JPEG)");
}

Picture decode_picture(std::string_view bytes, const std::string& name) {
  if (is_png(bytes)) {
    PngReader reader(bytes, name, Use::texture);
    return decode_png(reader, name);
  }
  if (is_jpeg(bytes)) return decode_jpeg(bytes, name);
  fail(Use::texture, name, bytes.empty() ? "the picture is empty" : "not a PNG or JPEG file (vkray's textures are PNG or JPEG)");
}

Picture decode_png_image(std::FILE* file, const std::string& name) {
  PngReader reader(file, name, Use::image_file);
  try {
    return decode_png(reader, name);
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(name, reader.width, reader.height);
  }
}

}  // namespace vkray
