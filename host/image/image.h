// Linear-radiance images and the files they are written to: 8-bit sRGB PNG, 32-bit float PFM, and
// OpenEXR (image/exr.h, which also writes the first-hit passes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include <glm/glm.hpp>

#include "image/display.h"

namespace vkray {

class AtomicFile;
struct LimitError;

// The largest side of an image vkray renders or reads: far from overflow in any size arithmetic.
constexpr uint32_t kMaxImageSide = 16384;

struct Image {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<glm::vec3> pixels;  // linear radiance, row-major, top row first

  Image() = default;
  Image(uint32_t w, uint32_t h) : width(w), height(h), pixels(size_t(w) * h, glm::vec3(0.0f)) {}
  glm::vec3& at(uint32_t x, uint32_t y) { return pixels[size_t(y) * width + x]; }
  const glm::vec3& at(uint32_t x, uint32_t y) const { return pixels[size_t(y) * width + x]; }
};

// round(255 * sRGB_encode(clamp(linear, 0, 1))), the PNG encoding of the shading contract.
// encode_srgb8 gives exactly encode_srgb8_by_formula's result, from a table (tests check every float
// in [0, 1] that matters: each threshold and its neighbours).
uint8_t encode_srgb8(float linear);
uint8_t encode_srgb8_by_formula(float linear);
// The sRGB transfer function, from an encoded fraction of full scale to linear light;
// decode_srgb8(v) is decode_srgb(v / 255.0f).
float decode_srgb(float encoded);
float decode_srgb8(uint8_t encoded);

// PNG (8-bit sRGB, through `display`: image/display.h) and PFM (32-bit float linear, rows bottom to top, little-endian) files, each
// written under a temporary name in the same folder and renamed into place, so that a failure never
// leaves a partial image. Throw OutputError. write_image (image_file.h) picks one by extension.
void write_png(const Image& image, const std::filesystem::path& file, const DisplayTransform& display = {});
void write_pfm(const Image& image, const std::filesystem::path& file);
// The PFM's bytes into `out`, which the caller commits (with a file that must change with it).
void write_pfm(const Image& image, AtomicFile& out);

// Readers of parts, tests and tools. A header's size is checked against the file's (a PFM's exactly)
// and against kMaxImageSide before anything is allocated for it. Throw InputError naming the file;
// LimitError ("out of host memory") when an image the file does hold does not fit in memory.
// read_png returns linear values, its samples decoded from sRGB as a texture's are (image/decode.h):
// any bit depth or colour type, an 8-bit v and a 16-bit 257 v alike, alpha dropped, and no
// colour-space chunk (gAMA, cHRM, iCCP, sRGB) applied. For a file write_png wrote, each value is
// decode_srgb8 of the byte stored, so that encode_srgb8 gives that byte back.
Image read_pfm(const std::filesystem::path& file);
Image read_png(const std::filesystem::path& file);

// What a reader throws when an allocation for pixels its file has been checked to hold fails: the
// machine's limit ("FILE: out of host memory for its W x H pixels"), not a bug.
LimitError out_of_host_memory(const std::filesystem::path& file, uint32_t width, uint32_t height);

}  // namespace vkray
