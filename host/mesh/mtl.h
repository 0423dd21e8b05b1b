// Wavefront material libraries (.mtl), the materials an OBJ file's faces name: the diffuse colour
// (Kd) and its texture (map_Kd), the emitted colour (Ke) and its texture (map_Ke), the dissolve (d,
// or Tr = 1 - d) and its texture (map_d). What vkray cannot render of them (bump maps, other maps,
// texture offsets and scales) is named in a warning, once a file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "scene/texture.h"

namespace vkray {

struct MtlTexture {
  std::filesystem::path file;  // relative to the .mtl's folder, as written; empty: none
  TextureWrap wrap = TextureWrap::repeat;  // "-clamp on": clamp_to_edge
};

struct MtlMaterial {
  std::string name;
  glm::vec3 diffuse{0.8f};  // Kd (1 when absent but map_Kd is given, so that the texture shows as it is)
  glm::vec3 emission{0.0f};  // Ke
  MtlTexture diffuse_map;    // map_Kd: multiplies Kd
  MtlTexture emission_map;   // map_Ke: multiplies Ke
  float opacity = 1.0f;      // d (1 - Tr): how much of the surface is there
  MtlTexture opacity_map;    // map_d: its alpha, or its grey where it has none, multiplies d
};

struct MtlLibrary {
  std::vector<MtlMaterial> materials;
  std::vector<std::string> warnings;
};

// Throws MeshError naming the file and the line: a colour that is not three finite numbers, a
// statement before the first newmtl, a map without a file name.
MtlLibrary parse_mtl(std::string_view text, const std::filesystem::path& file);

}  // namespace vkray
