#include "mesh/obj.h"

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cctype>
#include <cmath>
#include <string>

#include <tiny_obj_loader.h>

#include "base/errors.h"

namespace vkray {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw MeshError(file.string() + ": " + what);
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

void check_finite(const std::filesystem::path& file, const Mesh& mesh) {
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3& p = mesh.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      fail(file, "vertex " + std::to_string(i) + " has a coordinate that is not a finite number");
  }
}

// tinyobjloader reads a number it cannot parse as 0, silently; check every vertex line first.
void check_obj_vertices(const std::filesystem::path& file, std::string_view text) {
  size_t line_number = 0;
  for (size_t at = 0; at < text.size();) {
    const size_t end = std::min(text.find('\n', at), text.size());
    ++line_number;
    std::string_view line(text.data() + at, end - at);
    at = end + 1;
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
    line.remove_prefix(2);
    for (int k = 0; k < 3; ++k) {
      while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
      size_t length = 0;
      while (length < line.size() && !std::isspace(static_cast<unsigned char>(line[length]))) ++length;
      const std::string_view token = line.substr(0, length);
      double value = 0;
      const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (token.empty() || ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(value) ||
          std::abs(value) > FLT_MAX)
        fail(file.string() + ":" + std::to_string(line_number),
             "vertex coordinate \"" + printable(token) + "\" is not a finite 32-bit number");
      line.remove_prefix(length);
    }
  }
}

}  // namespace

Mesh parse_obj(const std::string& text, const std::filesystem::path& file) {
  check_obj_vertices(file, text);

  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // done below, so that polygons can be counted
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  // tinyobjloader's errors carry the line ("... line 12 ..."); pass them on verbatim.
  if (!reader.ParseFromString(text, "", config)) fail(file, trim(reader.Error()));
  const tinyobj::attrib_t& attrib = reader.GetAttrib();

  Mesh mesh;
  mesh.positions.resize(attrib.vertices.size() / 3);
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    mesh.positions[i] = {attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
  check_finite(file, mesh);

  bool all_normals = true;
  std::vector<std::array<glm::vec3, 3>> normals;
  size_t face_number = 0;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t offset = 0;
    for (const unsigned char corners : shape.mesh.num_face_vertices) {
      const auto* face = &shape.mesh.indices[offset];
      offset += corners;
      ++face_number;
      if (corners < 3) fail(file, "face " + std::to_string(face_number) + " has fewer than 3 vertices");
      mesh.polygons_split += corners > 3;
      for (unsigned c = 0; c < corners; ++c) {
        if (face[c].vertex_index < 0 || size_t(face[c].vertex_index) >= mesh.positions.size())
          fail(file, "face " + std::to_string(face_number) + ": vertex index out of range (the file has " +
                         std::to_string(mesh.positions.size()) + " vertices)");
        if (face[c].normal_index < 0 || size_t(face[c].normal_index) * 3 + 2 >= attrib.normals.size()) all_normals = false;
      }
      // A fan from the first corner: exact for the convex polygons OBJ files hold.
      for (unsigned c = 1; c + 1 < corners; ++c) {
        mesh.triangles.push_back({uint32_t(face[0].vertex_index), uint32_t(face[c].vertex_index),
                                  uint32_t(face[c + 1].vertex_index)});
        if (all_normals) {
          auto n = [&](unsigned k) {
            const size_t i = size_t(face[k].normal_index) * 3;
            return glm::vec3(attrib.normals[i], attrib.normals[i + 1], attrib.normals[i + 2]);
          };
          normals.push_back({n(0), n(c), n(c + 1)});
        }
      }
    }
  }
  if (all_normals && normals.size() == mesh.triangles.size()) mesh.corner_normals = std::move(normals);
  return mesh;
}

}  // namespace vkray
