// Tangents for normal maps where a mesh's file gives none: MikkTSpace (third_party/mikktspace), the
// tangent space glTF requires and the one normal maps are baked in by Blender, Substance and xNormal.
#pragma once

#include <array>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace vkray {

// One triangle as MikkTSpace reads it: its corners' positions, normals (the vertex normals, or the
// face's normal at every corner for a flat triangle) and texture coordinates (glTF's: v runs down
// the picture).
struct TangentTriangle {
  std::array<glm::vec3, 3> position;
  std::array<glm::vec3, 3> normal;
  std::array<glm::vec2, 3> uv;
};

// Each corner's tangent: xyz the unit direction along which u grows, w = +-1 such that
// w cross(normal, tangent) is the direction in which v falls (glTF's TANGENT). MikkTSpace welds
// corners that agree in position, normal and texture coordinate, so a mesh's triangles are given
// together. Throws std::bad_alloc when MikkTSpace runs out of memory.
std::vector<std::array<glm::vec4, 3>> mikktspace_tangents(std::span<const TangentTriangle> triangles);

}  // namespace vkray
