// Vertex normals for meshes whose files have none.
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

namespace vkray {

// Area-weighted vertex normals per triangle corner. Vertices are welded by position first, so a
// mesh saved with duplicated vertices (the Utah teapot's patch seams) still shades smoothly across
// its seams. A vertex only on zero-area triangles gets a zero normal.
std::vector<std::array<glm::vec3, 3>> area_weighted_normals(const std::vector<std::array<glm::vec3, 3>>& triangles);

}  // namespace vkray
