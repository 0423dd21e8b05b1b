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
#include <iomanip>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>
#include <system_error>
#include <thread>
#include <mutex>
#include <condition_variable>

#include <png.h>

#include "base/atomic_file.h"
#include "base/check.h"
#include "base/errors.h"
#include "base/interrupt.h"
#include "image/decode.h"
#include "image/display.h"

namespace vkray {
namespace {

// libpng reports errors through longjmp; this handler turns them into a message instead.
[[noreturn]] void png_failed(png_structp png, png_const_charp message) {
  auto* error = static_cast<std::string*>(png_get_error_ptr(png));
  *error = message;
  // libpng's "Write Error" comes from a failed fwrite(): say why (a full disk, a size limit).
  if (errno != 0) *error += std::string(": ") + std::strerror(errno);
  png_longjmp(png, 1);
}

// The image's rows as 8-bit sRGB, converted on a thread of their own a block of rows ahead of the
// reader, so that converting and compressing overlap (a 4096 x 4096 image: 145 and 180 ms).
class SrgbRows {
 public:
  SrgbRows(const Image& image, const DisplayTransform& display) : image_(image), display_(display), row_bytes_(size_t(image.width) * 3) {
    encode_srgb8(0.5f);  // builds the table here, where an exception can still be thrown
    for (auto& block : blocks_) block.resize(row_bytes_ * kRowsPerBlock);
    try {
      thread_ = std::thread([this] { convert(); });
    } catch (const std::system_error&) {  // no thread to be had (a process or memory limit): row() converts
    }
  }
  ~SrgbRows() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  SrgbRows(const SrgbRows&) = delete;
  SrgbRows& operator=(const SrgbRows&) = delete;

  // Row y, asked for in order from 0: valid until a row of the next block is asked for.
  const png_byte* row(uint32_t y) {
    if (!thread_.joinable()) {  // converted here, a row at a time
      png_byte* out = blocks_[0].data();
      for (uint32_t x = 0; x < image_.width; ++x)
        encode_pixel(x, y, out);
      return blocks_[0].data();
    }
    const uint32_t block = y / kRowsPerBlock;
    std::unique_lock lock(mutex_);
    if (block > released_) {
      released_ = block;  // every earlier block is read: the thread may fill its buffer again
      changed_.notify_all();
    }
    changed_.wait(lock, [&] { return converted_ > block; });
    return blocks_[block % 2].data() + size_t(y % kRowsPerBlock) * row_bytes_;
  }

 private:
  static constexpr uint32_t kRowsPerBlock = 64;

  void encode_pixel(uint32_t x, uint32_t y, png_byte*& out) const {
    display_.encode(image_.at(x, y), out);
    out += 3;
  }

  void convert() {
    for (uint32_t block = 0; block * kRowsPerBlock < image_.height; ++block) {
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || block < released_ + 2; });
        if (stop_) return;
      }
      png_byte* out = blocks_[block % 2].data();
      const uint32_t end = std::min(image_.height, (block + 1) * kRowsPerBlock);
      for (uint32_t y = block * kRowsPerBlock; y < end; ++y)
        for (uint32_t x = 0; x < image_.width; ++x)
          encode_pixel(x, y, out);
      {
        std::lock_guard lock(mutex_);
        converted_ = block + 1;
      }
      changed_.notify_all();
    }
  }

  const Image& image_;
  const DisplayTransform display_;
  const size_t row_bytes_;
  std::vector<png_byte> blocks_[2];
  std::mutex mutex_;
  std::condition_variable changed_;
  uint32_t converted_ = 0, released_ = 0;  // blocks converted; blocks before `released_` are read
  bool stop_ = false;
  std::thread thread_;
};

// Row by row, so that a Ctrl-C stops even a 16384x16384 image within a row (the whole image takes
// seconds to compress). `rows` is made before the setjmp and outlives any jump back to it; no C++
// object lives across a libpng call after it.
//
// Speed over size: the "up" filter alone and zlib level 1 wrote a 4096 x 4096 Cornell box in 180 ms
// (1.47 MB) where libpng's defaults (every filter tried per row, level 6) took 870 ms (0.77 MB).
bool encode_png(const Image& image, const DisplayTransform& display, FILE* out, std::string& error) {
  SrgbRows rows(image, display);  // first: it may throw (no memory, no thread), and nothing is there to leak yet
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, png_failed, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    error = "out of memory";
    return false;
  }
  bool interrupted = false;
  errno = 0;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, out);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  png_set_compression_level(png, 1);
  png_set_IHDR(png, info, image.width, image.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);  // the chunk libpng's simplified writer wrote
  png_write_info(png, info);
  for (uint32_t y = 0; y < image.height && !(interrupted = interrupt_requested()); ++y)
    png_write_row(png, rows.row(y));
  if (!interrupted) png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

void write_png(const Image& image, const std::filesystem::path& file, const DisplayTransform& display) {
  AtomicFile out(file);
  std::string error;
  if (!encode_png(image, display, out.get(), error)) throw OutputError(file.string() + ": PNG write failed: " + error);
  throw_if_interrupted();
  out.commit();
}

void write_pfm(const Image& image, const std::filesystem::path& file) {
  AtomicFile out(file);
  write_pfm(image, out);
  out.commit();
}

void write_pfm(const Image& image, AtomicFile& out) {
  static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
  std::fprintf(out.get(), "PF\n%u %u\n-1.0\n", image.width, image.height);
  for (uint32_t row = image.height; row-- > 0;) {  // PFM stores the bottom row first
    throw_if_interrupted();
    std::fwrite(&image.at(0, row), sizeof(glm::vec3), image.width, out.get());
  }
}

uint8_t encode_srgb8_by_formula(float linear) {
  const float c = linear > 0.0f ? std::min(linear, 1.0f) : 0.0f;  // NaN encodes as 0
  const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<uint8_t>(std::lround(255.0f * encoded));
}

namespace {

// encode_srgb8 by table. The floats in [0, 1] fall into buckets by the top 16 bits of their bit
// pattern (sign, exponent, 7 bits of mantissa); across one bucket the formula's result rises by at
// most 1 (a bucket spans at most 0.66 of an 8-bit step, at [0.5, 0.5039); checked as the table is
// built), so each bucket holds the encoding at its start and the first float where it rises, found
// by bisection over the bit patterns. The formula is monotonic in its argument; tests compare the
// two on every float in [0, 1] where they could differ.
struct Srgb8Bucket {
  float rise;  // the first float of the bucket encoded as `value + 1`; infinity when none is
  uint8_t value;
};
constexpr uint32_t kBucketShift = 16;
const uint32_t kOneBits = std::bit_cast<uint32_t>(1.0f);

std::vector<Srgb8Bucket> srgb8_buckets() {
  std::vector<Srgb8Bucket> buckets((kOneBits >> kBucketShift) + 1);
  for (uint32_t i = 0; i < buckets.size(); ++i) {
    const uint32_t first = i << kBucketShift, last = std::min(((i + 1) << kBucketShift) - 1, kOneBits);
    const uint8_t value = encode_srgb8_by_formula(std::bit_cast<float>(first));
    const uint8_t end = encode_srgb8_by_formula(std::bit_cast<float>(last));
    VKRAY_CHECK(end <= value + 1, "an sRGB table bucket spans at most one 8-bit step");
    float rise = std::numeric_limits<float>::infinity();
    if (end > value) {
      uint32_t low = first, high = last;  // encode(high) > value
      while (low < high) {
        const uint32_t middle = low + (high - low) / 2;
        if (encode_srgb8_by_formula(std::bit_cast<float>(middle)) > value) high = middle;
        else low = middle + 1;
      }
      rise = std::bit_cast<float>(low);
    }
    buckets[i] = {rise, value};
  }
  return buckets;
}

}  // namespace

uint8_t encode_srgb8(float linear) {
  // A table lookup and a comparison instead of a pow(): a 4096 x 4096 PNG spent 0.7 s in pow().
  static const std::vector<Srgb8Bucket> buckets = srgb8_buckets();
  if (!(linear > 0.0f)) return 0;  // NaN encodes as 0
  if (linear >= 1.0f) return 255;
  const Srgb8Bucket& bucket = buckets[std::bit_cast<uint32_t>(linear) >> kBucketShift];
  return static_cast<uint8_t>(bucket.value + (linear >= bucket.rise ? 1 : 0));
}

float decode_srgb(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float decode_srgb8(uint8_t encoded) { return decode_srgb(float(encoded) / 255.0f); }

LimitError out_of_host_memory(const std::filesystem::path& file, uint32_t width, uint32_t height) {
  return LimitError(file.string() + ": out of host memory for its " + std::to_string(width) + " x " +
                    std::to_string(height) + " pixels");
}

namespace {

Image allocate_image(const std::filesystem::path& file, uint32_t width, uint32_t height) {
  try {
    return Image(width, height);
  } catch (const std::bad_alloc&) {
    throw out_of_host_memory(file, width, height);
  }
}

}  // namespace

Image read_pfm(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) throw InputError(file.string() + ": not found, or not a regular file");
  const uintmax_t file_bytes = std::filesystem::file_size(file, error);
  std::ifstream in(file, std::ios::binary);
  if (!in || error) throw InputError(file.string() + ": cannot open");
  std::string magic;
  uint32_t width = 0, height = 0;
  float scale = 0.0f;
  in >> std::setw(2) >> magic >> width >> height >> scale;
  in.get();  // the single whitespace byte after the header
  if (!in || magic != "PF" || scale >= 0.0f || width == 0 || height == 0)
    throw InputError(file.string() + ": not a little-endian RGB PFM file");
  // The header's size must be the file's, before anything that large is allocated.
  const uint64_t data_bytes = uint64_t(width) * height * sizeof(glm::vec3);
  const std::streamoff header_bytes = in.tellg();
  const std::string claim = file.string() + ": a PFM header of " + std::to_string(width) + " x " + std::to_string(height) +
                            " pixels in a file of " + std::to_string(file_bytes) + " bytes";
  if (width > kMaxImageSide || height > kMaxImageSide)
    throw InputError(claim + " (vkray reads up to " + std::to_string(kMaxImageSide) + " pixels on a side)");
  if (header_bytes < 0 || file_bytes != uint64_t(header_bytes) + data_bytes)
    throw InputError(claim + " (" + std::to_string(uint64_t(header_bytes)) + " of header and " + std::to_string(data_bytes) +
                     " of pixels)");
  Image image = allocate_image(file, width, height);
  for (uint32_t row = height; row-- > 0;) {
    throw_if_interrupted();
    in.read(reinterpret_cast<char*>(&image.at(0, row)), std::streamsize(sizeof(glm::vec3) * width));
  }
  if (!in) throw InputError(file.string() + ": truncated PFM data");
  return image;
}

namespace {

// A picture's colour samples (its alpha, if any, dropped) from sRGB to linear, through a table of
// every value a sample of its depth can hold: v / max_value decoded once. An 8-bit v and a 16-bit
// 257 v are the same quotient, rounded once, so they are the same light; 8-bit values are exactly
// decode_srgb8's, the inverse of write_png's encode_srgb8.
template <typename Sample>
void decode_colour(const std::vector<Sample>& rgba, uint32_t max_value, Image& image) {
  std::vector<float> linear(size_t(max_value) + 1);
  for (uint32_t v = 0; v <= max_value; ++v) linear[v] = decode_srgb(float(v) / float(max_value));
  for (size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = {linear[rgba[4 * i]], linear[rgba[4 * i + 1]], linear[rgba[4 * i + 2]]};
}

struct FileCloser {
  void operator()(FILE* file) const { std::fclose(file); }
};

}  // namespace

Image read_png(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) throw InputError(file.string() + ": not found, or not a regular file");
  const std::unique_ptr<FILE, FileCloser> in(std::fopen(file.c_str(), "rb"));
  if (!in) throw InputError(file.string() + ": cannot open: " + std::strerror(errno));
  // The decoder textures use: the samples as stored, no colour-space chunk applied.
  const Picture picture = decode_png_image(in.get(), file.string());
  Image image = allocate_image(file, picture.width, picture.height);
  if (picture.sixteen_bit()) decode_colour(picture.rgba16, 65535, image);
  else decode_colour(picture.rgba, 255, image);
  return image;
}

}  // namespace vkray
