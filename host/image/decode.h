// PNG and JPEG files decoded to RGBA samples: the pictures textures are made of, and the PNG image
// files read_png (image.h) reads, so that a PNG's samples mean the same wherever vkray reads it.
// libpng and libjpeg-turbo (TurboJPEG) do the decoding; a picture's size is read from its header and
// checked against vkray's limits before any pixel memory is allocated.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace vkray {

// The largest picture vkray decodes: 16384 on a side (every GPU's texture limit, too), and at most
// 2^26 pixels (a 8192 x 8192 picture), which as half-float RGBA take 512 MiB on the device.
constexpr uint32_t kMaxPictureSide = 16384;
constexpr uint64_t kMaxPicturePixels = uint64_t(1) << 26;

// A picture's samples as its file stores them, 4 a pixel (RGBA), row-major, top row first: colour as
// encoded (sRGB for colour data), alpha linear. No colour-space metadata of the file (PNG gAMA, cHRM,
// iCCP, sRGB; JPEG ICC profiles) is applied: glTF requires them ignored, and so does every texture.
struct Picture {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> rgba;     // 8-bit samples (JPEG, and PNG of 1 to 8 bits scaled to 8), or
  std::vector<uint16_t> rgba16;  // 16-bit samples (a 16-bit PNG, kept at full precision)
  bool has_alpha = false;        // the file has alpha (or a transparent colour); without, alpha is full scale

  bool sixteen_bit() const { return !rgba16.empty(); }
};

// Whether the bytes start like a PNG or a JPEG file (by their signature, not a name's extension).
bool is_png(std::string_view bytes);
bool is_jpeg(std::string_view bytes);

// The size a PNG or JPEG file's header gives, read without decoding any pixel and checked against
// the limits above. Throws SceneError or LimitError as decode_picture does.
struct PictureSize {
  uint32_t width = 0;
  uint32_t height = 0;
};
PictureSize picture_size(std::string_view bytes, const std::string& name);

// Decodes a PNG (any bit depth and colour type: a palette, greyscale and fewer than 8 bits are
// expanded, tRNS becomes alpha, 16 bits stay 16) or a JPEG (greyscale, YCbCr or RGB; CMYK is
// refused). Greyscale becomes grey RGB; a missing alpha is full scale. Throws SceneError
// "<name>: <why>": an unknown format, a damaged file, a size past the limits above.
Picture decode_picture(std::string_view bytes, const std::string& name);

// A PNG image file (read_png, image.h), decoded as decode_picture decodes a texture's PNG but read
// from `file` as libpng asks for its bytes (an image may be far larger than a texture) and held to
// an image's limit, kMaxImageSide on a side (image.h), instead of a picture's. Throws InputError
// "<name>: <why>" (not a PNG file, a damaged one, a size past the limit), LimitError when its pixels
// do not fit in host memory.
Picture decode_png_image(std::FILE* file, const std::string& name);

}  // namespace vkray
