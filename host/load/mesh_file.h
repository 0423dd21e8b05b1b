// Mesh files by their extension: .obj (obj.h) or .ply (ply.h).
#pragma once

#include <filesystem>
#include <string_view>

#include "mesh/mesh.h"

namespace vkray {

// Reads an .obj or .ply file. Throws MeshError naming the file and the line or the element
// ("face 12", "vertex 7") that is wrong: a missing or unreadable file, an unknown format, an index
// out of range, a coordinate that is NaN or infinite, a mesh without faces.
Mesh load_mesh(const std::filesystem::path& file);

// The same from the file's bytes already in memory; `name` gives the format (by extension) and is
// the file named in messages.
Mesh parse_mesh(std::string_view bytes, const std::filesystem::path& name);

}  // namespace vkray
