// Textures as a scene holds them: pictures decoded to linear half-float RGBA, shared by the
// materials that use them, and how a material samples one (glTF's sampler: wrap modes and filter).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace vkray {

struct Picture;

// The values are the shader's (VKRAY_WRAP_* and VKRAY_FILTER_* in shaders/shared/scene_layout.h).
// All the textures of a scene together: 2^28 texels, 2 GiB as half-float RGBA. Checked from each
// picture's header before it is decoded.
constexpr uint64_t kMaxSceneTexels = uint64_t(1) << 28;

enum class TextureWrap : uint32_t { repeat = 0, clamp_to_edge = 1, mirrored_repeat = 2 };
enum class TextureFilter : uint32_t { linear = 0, nearest = 1 };

struct Texture {
  std::string name;  // where it came from, for messages: "meshes/crate.png", "box.glb: images[0]"
  uint32_t width = 0;
  uint32_t height = 0;
  // Half floats, 4 a texel (RGBA), row-major, top row first: the colour decoded from sRGB to linear,
  // alpha as stored. Both renderers read these same values (the GPU as an RGBA16F texel buffer).
  std::vector<uint16_t> texels;

  // Texel (x, y) as floats.
  glm::vec4 texel(uint32_t x, uint32_t y) const;
};

// What a picture file is read as: colour (decoded from sRGB, as base-colour and emissive textures
// are), data (linear: metallic-roughness, normal maps), or opacity (linear, into alpha: the
// picture's alpha, or its grey, its red, where it has no alpha, as an .mtl file's map_d).
enum class TextureUse { colour, data, opacity };

// A picture's colour decoded from sRGB (`srgb`, as base-colour and emissive textures are) or taken as
// linear, rounded to half floats.
Texture make_texture(const Picture& picture, std::string name, bool srgb = true);

// A PNG or JPEG file read and decoded (image/decode.h) for `use`. Throws SceneError naming the file.
Texture load_texture(const std::filesystem::path& file, TextureUse use = TextureUse::colour);

// How a material samples a texture; `texture` is an index into Scene::textures, -1 for none.
struct TextureRef {
  int32_t texture = -1;
  TextureWrap wrap_s = TextureWrap::repeat;  // along u (the picture's rows)
  TextureWrap wrap_t = TextureWrap::repeat;  // along v (its columns)
  TextureFilter filter = TextureFilter::linear;
  // The primitive's texture coordinate set it reads: 0, Triangle::uv; 1, Triangle::uv1.
  uint32_t texcoord = 0;
  // The affine map from a primitive's texture coordinate (u, v) to the texture's: u' = dot(to_u,
  // (u, v, 1)), v' = dot(to_v, (u, v, 1)) (glTF's KHR_texture_transform); the identity by default.
  glm::vec3 to_u{1.0f, 0.0f, 0.0f};
  glm::vec3 to_v{0.0f, 1.0f, 0.0f};

  bool present() const { return texture >= 0; }
  bool transformed() const { return to_u != glm::vec3(1.0f, 0.0f, 0.0f) || to_v != glm::vec3(0.0f, 1.0f, 0.0f); }
  // The texture's coordinate at the primitive's `uv`.
  glm::dvec2 map(const glm::dvec2& uv) const {
    return {glm::dot(glm::dvec3(to_u), glm::dvec3(uv, 1.0)), glm::dot(glm::dvec3(to_v), glm::dvec3(uv, 1.0))};
  }
  bool operator==(const TextureRef&) const = default;
};

}  // namespace vkray
