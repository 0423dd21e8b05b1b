// Wavefront OBJ meshes, read by vkray's own parser.
//
// Why not tinyobjloader (Debian's 2.0.0~rc10): it reads a number it cannot parse as 0, keeps a face's
// corner count in an unsigned char (a face of 300 corners became 44), clamps an index past 2^31 to a
// valid vertex, and ends lines at a lone '\r' where a pre-check of vkray's did not, so that check
// missed lines. Checking its input line by line meant writing the parser twice; the part of OBJ
// vkray needs is small enough to parse once, checking every number where it is read.
#pragma once

#include <filesystem>
#include <string_view>

#include "mesh/mesh.h"

namespace vkray {

// Reads positions (v), faces (f; polygons of any number of corners split into fans) and, when every
// face has them, vertex normals (vn) and texture coordinates (vt); the material each face names
// (usemtl) and the files that define them (mtllib, read by mesh/mtl.h); other statements are skipped. A line ends at "\n", "\r\n" or a lone "\r"; '#' starts a comment. Throws
// MeshError naming the file and the line, and the face where there is one: a coordinate that is not
// a finite 32-bit number, "face 12: vertex index 9 is out of range (the file has 8 vertices)", an
// index that is not an integer, a corner not written v, v/vt, v//vn or v/vt/vn like the face's first.
Mesh parse_obj(std::string_view text, const std::filesystem::path& file);

}  // namespace vkray
