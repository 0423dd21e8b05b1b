// A triangle mesh as a mesh file holds it: what the readers (obj.h, ply.h) return and the scene
// loader places into the scene.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace vkray {

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;  // indices into positions
  // Per triangle corner, when the file has vertex normals for every face; empty otherwise.
  std::vector<std::array<glm::vec3, 3>> corner_normals;
  // Per triangle corner, when every face has texture coordinates (an OBJ file's vt); empty
  // otherwise. As glTF has them: (0, 0) is a picture's top left corner (OBJ's v is flipped).
  std::vector<std::array<glm::vec2, 3>> corner_uvs;
  size_t polygons_split = 0;  // faces with more than 3 vertices, triangulated

  // The materials the faces name (an OBJ file's usemtl), in order of first use, and each
  // triangle's index into them (kNoMaterial before the first usemtl); both empty when none is named.
  static constexpr uint32_t kNoMaterial = UINT32_MAX;
  std::vector<std::string> material_names;
  std::vector<uint32_t> triangle_materials;
  std::vector<std::string> material_libraries;  // the files that define them (mtllib), as written
};

}  // namespace vkray
