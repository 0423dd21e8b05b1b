#include "scene/texture.h"

#include <array>

#include <Imath/half.h>

#include "base/errors.h"
#include "base/input_file.h"
#include "image/decode.h"
#include "image/image.h"

namespace vkray {
namespace {

uint16_t half_bits(float value) { return Imath::half(value).bits(); }

}  // namespace

glm::vec4 Texture::texel(uint32_t x, uint32_t y) const {
  const uint16_t* t = &texels[(size_t(y) * width + x) * 4];
  glm::vec4 out;
  for (int c = 0; c < 4; ++c) out[c] = imath_half_to_float(t[c]);
  return out;
}

Texture make_texture(const Picture& picture, std::string name, bool srgb) {
  // Each of the 256 byte values once: decoded (or not) and rounded to a half float.
  std::array<uint16_t, 256> colour, linear;
  for (int v = 0; v < 256; ++v) {
    linear[size_t(v)] = half_bits(float(v) / 255.0f);
    colour[size_t(v)] = srgb ? half_bits(decode_srgb8(uint8_t(v))) : linear[size_t(v)];
  }
  Texture t;
  t.name = std::move(name);
  t.width = picture.width;
  t.height = picture.height;
  t.texels.resize(picture.rgba.size());
  for (size_t i = 0; i < picture.rgba.size(); i += 4) {
    for (size_t c = 0; c < 3; ++c) t.texels[i + c] = colour[picture.rgba[i + c]];
    t.texels[i + 3] = linear[picture.rgba[i + 3]];
  }
  return t;
}

Texture load_texture(const std::filesystem::path& file, bool srgb) {
  const InputFile input = read_input_file(file, kMaxPictureFileBytes);
  if (!input.error.empty()) throw SceneError(file.string() + ": " + (input.error == "not found" ? "texture file not found" : input.error));
  return make_texture(decode_picture(input.text, file.string()), file.string(), srgb);
}

}  // namespace vkray
