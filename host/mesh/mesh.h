// A triangle mesh as a mesh file holds it: what the readers (obj.h, ply.h) return and the scene
// loader places into the scene.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace vkray {

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::array<uint32_t, 3>> triangles;  // indices into positions
  // Per triangle corner, when the file has vertex normals for every face; empty otherwise.
  std::vector<std::array<glm::vec3, 3>> corner_normals;
  size_t polygons_split = 0;  // faces with more than 3 vertices, triangulated
};

}  // namespace vkray
