#include "mesh.h"

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <fstream>
#include <sstream>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tiny_obj_loader.h>

#include "errors.h"

namespace vkray {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw MeshError(file.string() + ": " + what);
}

// Text from a file, fit to quote in a one-line message: control and non-ASCII bytes become '?',
// and long text is shortened.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 60)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (text.size() > 60) out += "...";
  return out;
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

// vkray reads the PLY header itself before assimp sees the file, and refuses anything that is not
// a well-formed header: assimp 5.2.5 (Debian 12's) has known memory-safety bugs on malformed PLY
// (upstream #4306, #5310, #5717, #5739, #6620), and fuzz_ply corrupted the heap through a garbled
// header. It also checks that the file is large enough for the elements the header declares, so a
// header that claims a billion faces is refused at once instead of after seconds of allocation.
void check_ply_header(std::string_view bytes, const std::filesystem::path& file) {
  std::istringstream in{std::string(bytes.substr(0, std::min<size_t>(bytes.size(), 1 << 16)))};
  size_t line_number = 0;
  std::string line;
  auto bad = [&](const std::string& what) { fail(file.string() + ":" + std::to_string(line_number), what); };
  // Every header line, comments included, must be printable ASCII: assimp mis-parses binary bytes
  // in header lines (fuzz_ply found heap corruption through an obj_info line).
  auto next = [&]() -> bool {
    if (!std::getline(in, line)) return false;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (std::any_of(line.begin(), line.end(), [](char c) { return (c < 0x20 && c != '\t') || c >= 0x7f; }))
      bad("the PLY header has a non-printable byte: \"" + printable(line) + "\"");
    return true;
  };
  // Element and property names: letters, digits, '_' and '-'.
  auto check_name = [&](const std::string& name) {
    if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }))
      bad("bad PLY name \"" + printable(name) + "\"");
  };
  if (!next() || line != "ply") fail(file, "not a PLY file (no \"ply\" on the first line)");
  if (!next()) bad("the PLY header ends early");
  std::istringstream format_line(line);
  std::string keyword, format, version;
  format_line >> keyword >> format >> version;
  if (keyword != "format" || (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian") ||
      version != "1.0")
    bad("expected \"format ascii|binary_little_endian|binary_big_endian 1.0\", got \"" + printable(line) + "\"");
  const bool ascii = format == "ascii";

  struct Element {
    std::string name;
    uint64_t count = 0;
    uint64_t min_bytes = 0;  // per element: binary sizes, or one character and a separator per property (ASCII)
    std::vector<std::string> properties;
  };
  std::vector<Element> elements;
  auto type_size = [&](const std::string& type) -> uint64_t {
    static const std::pair<const char*, uint64_t> sizes[] = {
        {"char", 1}, {"uchar", 1}, {"int8", 1}, {"uint8", 1}, {"short", 2}, {"ushort", 2}, {"int16", 2}, {"uint16", 2},
        {"int", 4}, {"uint", 4}, {"int32", 4}, {"uint32", 4}, {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
    for (const auto& [name, size] : sizes)
      if (type == name) return size;
    bad("unknown PLY property type \"" + printable(type) + "\"");
    return 0;  // not reached: bad() throws
  };
  for (;;) {
    if (!next()) fail(file, "the PLY header has no end_header line (in its first 64 KiB)");
    std::istringstream words(line);
    std::string word, extra;
    words >> word;
    if (word == "end_header") {
      if (words >> extra) bad("unexpected text after end_header");
      break;
    }
    if (word == "comment" || word == "obj_info") continue;
    if (word == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      if (e.name.empty() || count.empty() || count.find_first_not_of("0123456789") != std::string::npos || count.size() > 18 ||
          (words >> extra))
        bad("expected \"element NAME COUNT\", got \"" + printable(line) + "\"");
      check_name(e.name);
      e.count = std::stoull(count);
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) bad("a property before any element");
      std::string type, name;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> name;
        const uint64_t count_size = type_size(count_type);
        type_size(item_type);
        elements.back().min_bytes += ascii ? 2 : count_size;  // the list's length; it may be empty
      } else {
        words >> name;
        const uint64_t size = type_size(type);  // checked for ASCII files too
        elements.back().min_bytes += ascii ? 2 : size;
      }
      if (name.empty() || (words >> extra)) bad("expected \"property TYPE NAME\", got \"" + printable(line) + "\"");
      check_name(name);
      elements.back().properties.push_back(name);
    } else {
      bad("unknown PLY header line \"" + printable(line) + "\"");
    }
  }
  const auto vertex = std::find_if(elements.begin(), elements.end(), [](const Element& e) { return e.name == "vertex"; });
  if (vertex == elements.end()) fail(file, "the PLY header declares no vertex element");
  for (const char* axis : {"x", "y", "z"})
    if (std::find(vertex->properties.begin(), vertex->properties.end(), axis) == vertex->properties.end())
      fail(file, std::string("the vertex element has no \"") + axis + "\" property");

  const auto header_end = static_cast<uint64_t>(in.tellg());
  const uint64_t size = bytes.size();
  const uint64_t available = size > header_end ? size - header_end : 0;
  uint64_t needed = 0;
  for (const Element& e : elements) {
    const uint64_t per = std::max<uint64_t>(e.min_bytes, 1);
    if (e.count > available / per || needed > available - e.count * per)
      fail(file, "the header declares " + std::to_string(e.count) + " " + e.name + " elements, more than the " +
                     std::to_string(available) + " bytes after the header can hold");
    needed += e.count * per;
  }
}

Mesh parse_ply(std::string_view bytes, const std::filesystem::path& file) {
  Assimp::Importer importer;
  // No post-processing at all: every step assimp would run trusts the indices the file gave, and
  // fuzz_ply crashed SortByPType with garbage ones; ValidateDataStructure leaks when it rejects a
  // file (assimp 5.2.5). vkray itself skips points and lines, splits polygons and checks every
  // index below.
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), 0, "ply");
  if (!scene) fail(file, trim(importer.GetErrorString()));
  Mesh mesh;
  bool all_normals = true;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    const auto base = uint32_t(mesh.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v)
      mesh.positions.emplace_back(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    all_normals = all_normals && am->HasNormals();
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices < 3) continue;
      mesh.polygons_split += face.mNumIndices > 3;
      for (unsigned c = 0; c < face.mNumIndices; ++c)
        if (face.mIndices[c] >= am->mNumVertices)
          fail(file, "face " + std::to_string(f) + ": vertex index " + std::to_string(face.mIndices[c]) +
                         " out of range (the file has " + std::to_string(am->mNumVertices) + " vertices)");
      for (unsigned c = 1; c + 1 < face.mNumIndices; ++c) {
        mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[c], base + face.mIndices[c + 1]});
        if (am->HasNormals()) {
          auto n = [&](unsigned k) {
            const aiVector3D& a = am->mNormals[face.mIndices[k]];
            return glm::vec3(a.x, a.y, a.z);
          };
          mesh.corner_normals.push_back({n(0), n(c), n(c + 1)});
        }
      }
    }
  }
  if (!all_normals) mesh.corner_normals.clear();
  check_finite(file, mesh);
  return mesh;
}

}  // namespace

std::vector<std::array<glm::vec3, 3>> area_weighted_normals(const std::vector<std::array<glm::vec3, 3>>& triangles) {
  struct Key {
    uint32_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    size_t operator()(const Key& k) const { return (size_t(k.x) * 73856093u) ^ (size_t(k.y) * 19349663u) ^ (size_t(k.z) * 83492791u); }
  };
  auto key = [](const glm::vec3& p) {
    Key k;
    std::memcpy(&k, &p, sizeof k);
    return k;
  };
  std::unordered_map<Key, glm::vec3, Hash> sum;
  sum.reserve(triangles.size());
  for (const auto& t : triangles) {
    const glm::vec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);  // length = 2 * area: area-weighted
    for (const auto& p : t) sum[key(p)] += n;
  }
  std::vector<std::array<glm::vec3, 3>> normals(triangles.size());
  for (size_t i = 0; i < triangles.size(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      const glm::vec3 n = sum[key(triangles[i][k])];
      const float length = glm::length(n);
      normals[i][k] = length > 0 ? n / length : glm::vec3(0.0f);
    }
  return normals;
}

Mesh parse_mesh(std::string_view bytes, const std::filesystem::path& name) {
  std::string ext = name.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  Mesh mesh;
  if (ext == ".obj") {
    mesh = parse_obj(std::string(bytes), name);
  } else if (ext == ".ply") {
    check_ply_header(bytes, name);
    mesh = parse_ply(bytes, name);
  } else {
    fail(name, "unknown mesh format \"" + ext + "\" (expected .obj or .ply)");
  }
  if (mesh.triangles.empty()) fail(name, "the mesh has no faces");
  return mesh;
}

Mesh load_mesh(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) fail(file, "is a directory, not a mesh file");
  if (!std::filesystem::is_regular_file(file, ec)) fail(file, "mesh file not found");
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in) fail(file, "cannot read mesh file");
  return parse_mesh(bytes.str(), file);
}

}  // namespace vkray
