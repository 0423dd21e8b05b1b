// Wavefront OBJ meshes, read through tinyobjloader.
#pragma once

#include <filesystem>
#include <string>

#include "mesh/mesh.h"

namespace vkray {

// Reads positions, faces (polygons split into fans) and, when every face has them, vertex normals.
// Throws MeshError naming the file and the line (syntax errors, a coordinate that is not a finite
// 32-bit number) or the face ("face 12: vertex index out of range").
Mesh parse_obj(const std::string& text, const std::filesystem::path& file);

}  // namespace vkray
