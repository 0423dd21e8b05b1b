// Small assets made in code for the texture and glTF tests: pictures as PNG or JPEG bytes, and glTF
// files built element by element, so that each test states exactly what its file holds.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vkray::test {

// A picture as 8-bit sRGB RGB bytes, row-major from the top.
struct TestPicture {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;
};
// 2 x 2: red, green / blue, white.
TestPicture four_colours();
std::string png_bytes(const TestPicture& picture);
std::string jpeg_bytes(const TestPicture& picture, int quality = 100);
// A PNG signature and header claiming width x height pixels, with no pixel data after it (libpng
// refuses past 1000000 on a side itself).
std::string png_header_only(uint32_t width, uint32_t height);

void write_file(const std::filesystem::path& file, const std::string& bytes);

// A glTF file under construction: `doc` is its JSON (asset, one scene with no nodes yet), `bin` its
// one buffer. Helpers append accessors and return their index.
struct GltfBuilder {
  GltfBuilder();
  nlohmann::json doc;
  std::string bin;

  int accessor(const std::vector<float>& values, const char* type);            // FLOAT components
  int indices(const std::vector<uint32_t>& values, int component_type = 5125);  // UNSIGNED_INT by default
  // A unit quad in z = 0 facing +z, (-1,-1) to (1,1), with TEXCOORD_0 (0,0) at its top left, as mesh
  // and node; returns the node's index. `material` -1: none.
  int quad(int material = -1, bool indexed = true);
  int material(const nlohmann::json& m);
  // A texture (and its image) from PNG or JPEG bytes kept in the buffer; `sampler` may be null.
  int texture(const std::string& picture, const nlohmann::json& sampler = nullptr);

  std::string gltf() const;  // the buffer as a data: URI
  std::string glb() const;
};

}  // namespace vkray::test
