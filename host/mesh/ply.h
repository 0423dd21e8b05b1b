// PLY meshes (ASCII, binary little- and big-endian), read by vkray's own bounds-checked reader.
//
// Why not a library: the one Debian 12 packages, assimp 5.2.5, has known memory-safety bugs on
// malformed PLY (upstream #4306, #5310, #5717, #5739, #6620), and fuzz_ply found five of them within
// minutes (docs/design.md, "Why vkray reads PLY itself"). PLY is a small format; this reader checks every count against the
// bytes that are left before it reads or allocates anything.
#pragma once

#include <filesystem>
#include <string_view>

#include "mesh/mesh.h"

namespace vkray {

// Reads the "vertex" element's x, y, z (and nx, ny, nz when all three are there) and the "face"
// element's vertex_indices (or vertex_index) list; other elements and properties are skipped.
// Polygons are split into fans. Throws MeshError naming the file and the header line, or the
// element ("face 12") and, in ASCII files, the line that is wrong.
Mesh parse_ply(std::string_view bytes, const std::filesystem::path& file);

}  // namespace vkray
