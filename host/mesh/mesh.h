// Triangle meshes from files: Wavefront OBJ (tinyobjloader) and PLY, ASCII or binary (ply.h).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string_view>
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

// Reads an .obj or .ply file. Throws MeshError naming the file and the line (OBJ syntax errors) or
// the element ("face 12", "vertex 7") that is wrong: a missing or unreadable file, an unknown
// format, an index out of range, a coordinate that is NaN or infinite.
Mesh load_mesh(const std::filesystem::path& file);

// The same from the file's bytes already in memory; `name` gives the format (by extension) and is
// the file named in messages.
Mesh parse_mesh(std::string_view bytes, const std::filesystem::path& name);

// Area-weighted vertex normals per triangle corner, for meshes whose files have none. Vertices
// are welded by position first, so a mesh saved with duplicated vertices (the Utah teapot's
// patch seams) still shades smoothly across its seams.
std::vector<std::array<glm::vec3, 3>> area_weighted_normals(const std::vector<std::array<glm::vec3, 3>>& triangles);

}  // namespace vkray
