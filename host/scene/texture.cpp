#include "scene/texture.h"

#include <vector>

#include <Imath/half.h>

#include "base/errors.h"
#include "base/input_file.h"
#include "image/decode.h"
#include "image/image.h"

namespace vkray {
namespace {

uint16_t half_bits(float value) { return Imath::half(value).bits(); }

// Each sample value of a depth once, decoded from sRGB (colour) or taken as linear (data and alpha),
// rounded to a half float. An 8-bit sample v and a 16-bit one v * 257 reach decode_srgb as the same
// float (v / 255 and 257 v / 65535 are one quotient, rounded once), so both depths decode alike.
std::vector<uint16_t> sample_halves(uint32_t max_value, bool srgb) {
  std::vector<uint16_t> halves(size_t(max_value) + 1);
  for (uint32_t v = 0; v <= max_value; ++v) {
    const float fraction = float(v) / float(max_value);
    halves[v] = half_bits(srgb ? decode_srgb(fraction) : fraction);
  }
  return halves;
}

template <typename Sample>
void fill_texels(const std::vector<Sample>& samples, uint32_t max_value, bool srgb, std::vector<uint16_t>& texels) {
  const std::vector<uint16_t> colour = sample_halves(max_value, srgb);
  const std::vector<uint16_t> linear = srgb ? sample_halves(max_value, false) : colour;
  texels.resize(samples.size());
  for (size_t i = 0; i < samples.size(); i += 4) {
    for (size_t c = 0; c < 3; ++c) texels[i + c] = colour[samples[i + c]];
    texels[i + 3] = linear[samples[i + 3]];
  }
}

}  // namespace

glm::vec4 Texture::texel(uint32_t x, uint32_t y) const {
  const uint16_t* t = &texels[(size_t(y) * width + x) * 4];
  glm::vec4 out;
  for (int c = 0; c < 4; ++c) out[c] = imath_half_to_float(t[c]);
  return out;
}

Texture make_texture(const Picture& picture, std::string name, bool srgb) {
  Texture t;
  t.name = std::move(name);
  t.width = picture.width;
  t.height = picture.height;
  if (picture.sixteen_bit())
    fill_texels(picture.rgba16, 65535, srgb, t.texels);
  else
    fill_texels(picture.rgba, 255, srgb, t.texels);
  return t;
}

Texture load_texture(const std::filesystem::path& file, TextureUse use) {
  const InputFile input = read_input_file(file, kMaxPictureFileBytes);
  if (!input.error.empty()) throw SceneError(file.string() + ": " + (input.error == "not found" ? "texture file not found" : input.error));
  Picture picture = decode_picture(input.text, file.string());
  if (use == TextureUse::opacity && !picture.has_alpha) {  // its grey is its alpha
    for (size_t i = 0; i < picture.rgba.size(); i += 4) picture.rgba[i + 3] = picture.rgba[i];
    for (size_t i = 0; i < picture.rgba16.size(); i += 4) picture.rgba16[i + 3] = picture.rgba16[i];
  }
  return make_texture(picture, file.string(), use == TextureUse::colour);
}

}  // namespace vkray
