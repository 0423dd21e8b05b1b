#include "image/image.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include <png.h>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

// libpng reports errors through longjmp; this handler turns them into a message instead.
[[noreturn]] void png_failed(png_structp png, png_const_charp message) {
  auto* error = static_cast<std::string*>(png_get_error_ptr(png));
  *error = message;
  // libpng's "Write Error" comes from a failed fwrite(): say why (a full disk, a size limit).
  if (errno != 0) *error += std::string(": ") + std::strerror(errno);
  png_longjmp(png, 1);
}

// Row by row, so that a Ctrl-C stops even a 16384x16384 image within a row (the whole image takes
// seconds to compress). `row` is made before the setjmp and outlives any jump back to it.
bool encode_png(const Image& image, FILE* out, std::string& error) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_failed, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    error = "out of memory";
    return false;
  }
  std::vector<png_byte> row(size_t(image.width) * 3);
  bool interrupted = false;
  errno = 0;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, out);
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);  // the chunk libpng's simplified writer wrote
  png_write_info(png, info);
  for (uint32_t y = 0; y < image.height && !(interrupted = interrupt_requested()); ++y) {
    for (uint32_t x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) row[size_t(x) * 3 + size_t(c)] = encode_srgb8(image.at(x, y)[c]);
    png_write_row(png, row.data());
  }
  if (!interrupted) png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

void write_png(const Image& image, const std::filesystem::path& file) {
  AtomicFile out(file);
  std::string error;
  if (!encode_png(image, out.get(), error)) throw OutputError(file.string() + ": PNG write failed: " + error);
  throw_if_interrupted();
  out.commit();
}

void write_pfm(const Image& image, const std::filesystem::path& file) {
  static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
  AtomicFile out(file);
  std::fprintf(out.get(), "PF\n%u %u\n-1.0\n", image.width, image.height);
  for (uint32_t row = image.height; row-- > 0;) {  // PFM stores the bottom row first
    throw_if_interrupted();
    std::fwrite(&image.at(0, row), sizeof(glm::vec3), image.width, out.get());
  }
  out.commit();
}

}  // namespace

uint8_t encode_srgb8(float linear) {
  const float c = linear > 0.0f ? std::min(linear, 1.0f) : 0.0f;  // NaN encodes as 0
  const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(255.0f * encoded));
}

float decode_srgb8(uint8_t encoded) {
  const float c = float(encoded) / 255.0f;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

bool is_supported_image_path(const std::filesystem::path& file) {
  const std::string ext = lower_extension(file);
  return ext == ".png" || ext == ".pfm";
}

void write_image(const Image& image, const std::filesystem::path& file) {
  const std::string ext = lower_extension(file);
  if (ext == ".png") return write_png(image, file);
  if (ext == ".pfm") return write_pfm(image, file);
  throw OutputError(file.string() + ": unknown image type \"" + ext + "\" (expected .png or .pfm)");
}

Image read_pfm(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open");
  std::string magic;
  uint32_t width = 0, height = 0;
  float scale = 0.0f;
  in >> magic >> width >> height >> scale;
  in.get();  // the single whitespace byte after the header
  if (!in || magic != "PF" || scale >= 0.0f || width == 0 || height == 0)
    throw InputError(file.string() + ": not a little-endian RGB PFM file");
  Image image(width, height);
  for (uint32_t row = height; row-- > 0;)
    in.read(reinterpret_cast<char*>(&image.at(0, row)), std::streamsize(sizeof(glm::vec3) * width));
  if (!in) throw InputError(file.string() + ": truncated PFM data");
  return image;
}

Image read_png(const std::filesystem::path& file) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, file.string().c_str()))
    throw InputError(file.string() + ": " + png.message);
  png.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> bytes(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, bytes.data(), 0, nullptr))
    throw InputError(file.string() + ": " + png.message);
  Image image(png.width, png.height);
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = {decode_srgb8(bytes[i * 3]), decode_srgb8(bytes[i * 3 + 1]), decode_srgb8(bytes[i * 3 + 2])};
  return image;
}

}  // namespace vkray
