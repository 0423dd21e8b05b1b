#include "mesh/obj.h"

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

// One of the three lists a face corner indexes into.
struct IndexedList {
  IndexedList(const char* index_name_, const char* plural_) : index_name(index_name_), plural(plural_) {}
  const char* index_name;  // in messages: "vertex index 9 is out of range (the file has 3 vertices)"
  const char* plural;
  size_t count = 0;        // read so far: a negative index counts back from here
  // The largest positive index seen, and where, checked once the whole file is read: a face may use
  // vertices defined after it.
  int64_t max_index = 0;
  std::string max_token;
  size_t max_line = 0, max_face = 0;
};

class ObjParser {
 public:
  ObjParser(std::string_view text, const std::filesystem::path& file) : text_(text), file_(file) {}

  Mesh parse() {
    for (std::string_view line; next_line(line);) {
      if (line_number_ % 4096 == 0) throw_if_interrupted();
      if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      tokens_.clear();
      for (size_t at = 0;;) {
        while (at < line.size() && is_space(line[at])) ++at;
        if (at == line.size()) break;
        size_t end = at;
        while (end < line.size() && !is_space(line[end])) ++end;
        tokens_.push_back(line.substr(at, end - at));
        at = end;
      }
      if (tokens_.empty()) continue;
      const std::string_view keyword = tokens_[0];
      if (keyword == "v") {
        numbers("vertex coordinate", 3, 7);  // x y z, then w or a colour (r g b) that vkray does not use
        mesh_.positions.push_back({coordinates_[0], coordinates_[1], coordinates_[2]});
        ++lists_[kVertex].count;
      } else if (keyword == "vn") {
        numbers("normal coordinate", 3, 3);
        normals_.push_back({coordinates_[0], coordinates_[1], coordinates_[2]});
        ++lists_[kNormal].count;
      } else if (keyword == "vt") {
        numbers("texture coordinate", 1, 3);
        for (const float c : coordinates_)  // the bound of world coordinates, which keeps interpolation finite
          if (!(std::abs(c) <= 1e9f)) fail("texture coordinate " + std::to_string(c) + " is past +-1e9");
        // OBJ's v runs up from the bottom of the picture, glTF's (vkray's) down from its top.
        texcoords_.push_back({coordinates_[0], 1.0f - (coordinates_.size() > 1 ? coordinates_[1] : 0.0f)});
        ++lists_[kTexture].count;
      } else if (keyword == "f") {
        face();
      } else if (keyword == "usemtl") {
        use_material(line);
      } else if (keyword == "mtllib") {
        for (size_t i = 1; i < tokens_.size(); ++i) mesh_.material_libraries.emplace_back(tokens_[i]);
      }
      // Anything else (o, g, s, l, p, ...) says nothing vkray uses.
    }
    for (const IndexedList& list : lists_)
      if (list.max_index > int64_t(list.count)) out_of_range(list, list.max_token, list.max_line, list.max_face);
    if (all_normals_) {
      mesh_.corner_normals.reserve(corner_normal_indices_.size());
      for (const auto& n : corner_normal_indices_) mesh_.corner_normals.push_back({normals_[n[0]], normals_[n[1]], normals_[n[2]]});
    }
    if (all_texcoords_) {
      mesh_.corner_uvs.reserve(corner_texcoord_indices_.size());
      for (const auto& t : corner_texcoord_indices_) mesh_.corner_uvs.push_back({texcoords_[t[0]], texcoords_[t[1]], texcoords_[t[2]]});
    }
    if (mesh_.material_names.empty()) mesh_.triangle_materials.clear();
    return std::move(mesh_);
  }

 private:
  // usemtl NAME: the faces after it have that material. The name is the rest of the line (names may
  // hold spaces).
  void use_material(std::string_view line) {
    const size_t at = line.find("usemtl") + 6;
    std::string name(line.substr(at));
    const auto space = [](char c) { return is_space(c); };
    while (!name.empty() && space(name.back())) name.pop_back();
    name.erase(name.begin(), std::find_if_not(name.begin(), name.end(), space));
    if (name.empty()) fail("usemtl without a material name");
    // Looked up by hash: a file naming thousands of materials costs no more per usemtl than one naming two.
    const auto [found, added] = material_index_.try_emplace(name, uint32_t(mesh_.material_names.size()));
    material_ = found->second;
    if (added) mesh_.material_names.push_back(std::move(name));
  }

  // Spaces between tokens. Tested by hand: std::string_view::find_first_of calls memchr on the set
  // for every character, which was a fifth of loading the bunny.
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }
  enum { kVertex, kTexture, kNormal };

  // A line ends at "\n", "\r\n" or a lone "\r" (old Mac files), the same for every kind of line.
  bool next_line(std::string_view& line) {
    if (at_ >= text_.size()) return false;
    size_t end = at_;
    while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
    line = text_.substr(at_, end - at_);
    at_ = end + 1;
    if (end + 1 < text_.size() && text_[end] == '\r' && text_[end + 1] == '\n') ++at_;
    ++line_number_;
    return true;
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw MeshError(file_.string() + ":" + std::to_string(line_number_) + ": " + what);
  }

  // tokens_[1..] as finite 32-bit numbers, from `min` to `max` of them, into coordinates_.
  void numbers(const char* what, size_t min, size_t max) {
    coordinates_.clear();
    for (size_t i = 1; i < tokens_.size(); ++i) {
      const std::string_view token = tokens_[i];
      double value = 0;
      const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(value) || std::abs(value) > FLT_MAX)
        fail(std::string(what) + " \"" + printable(token) + "\" is not a finite 32-bit number");
      coordinates_.push_back(float(value));
    }
    if (coordinates_.size() < min || coordinates_.size() > max)
      fail("expected " + (min == max ? std::to_string(min) : std::to_string(min) + " to " + std::to_string(max)) + " numbers after \"" +
           std::string(tokens_[0]) + "\", got " + std::to_string(coordinates_.size()));
  }

  [[noreturn]] void out_of_range(const IndexedList& list, std::string_view token, size_t line, size_t face) const {
    throw MeshError(file_.string() + ":" + std::to_string(line) + ": face " + std::to_string(face) + ": " + list.index_name +
                    " " + printable(token) + " is out of range (the file has " + std::to_string(list.count) + " " +
                    list.plural + (token.front() == '-' ? " before this line)" : ")"));
  }

  // One index of a corner: 1 is the first element, -1 the last one read so far. A positive index is
  // checked against the whole file's count at its end.
  uint32_t index(IndexedList& list, std::string_view token) {
    int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    const bool integer = !token.empty() && ptr == token.data() + token.size() && token.front() != '+';
    if (!integer || (ec != std::errc() && ec != std::errc::result_out_of_range))
      fail("face " + std::to_string(face_number_) + ": " + list.index_name + " \"" + printable(token) + "\" is not an integer");
    if (ec == std::errc::result_out_of_range) value = token.front() == '-' ? std::numeric_limits<int64_t>::min()
                                                                           : std::numeric_limits<int64_t>::max();
    if (value == 0 || (value < 0 && -(value + 1) >= int64_t(list.count)))
      out_of_range(list, token, line_number_, face_number_);
    if (value < 0) return uint32_t(int64_t(list.count) + value);
    if (value > list.max_index) {
      list.max_index = value;
      list.max_token = std::string(token);
      list.max_line = line_number_;
      list.max_face = face_number_;
    }
    return uint32_t(value - 1);  // when it does not fit, the check at the end fails
  }

  void face() {
    ++face_number_;
    const size_t corners = tokens_.size() - 1;
    if (corners < 3) fail("face " + std::to_string(face_number_) + ": " + std::to_string(corners) + " corners, a face needs at least 3");
    vertices_.clear();
    face_normals_.clear();
    face_texcoords_.clear();
    int first_form = -1;
    for (size_t c = 1; c < tokens_.size(); ++c) {
      // v, v/vt, v//vn or v/vt/vn, the same form at every corner of a face.
      const std::string_view corner = tokens_[c];
      std::string_view parts[3];
      size_t count = 0;
      for (size_t at = 0;; ++count) {
        const size_t slash = corner.find('/', at);
        if (count == 3) fail("face " + std::to_string(face_number_) + ": corner \"" + printable(corner) + "\" has more than 3 indices");
        parts[count] = corner.substr(at, slash == std::string_view::npos ? std::string_view::npos : slash - at);
        if (slash == std::string_view::npos) break;
        at = slash + 1;
      }
      ++count;
      const bool has_texture = count >= 2 && !parts[1].empty(), has_normal = count == 3;
      if (parts[0].empty() || (count == 2 && !has_texture) || (has_normal && parts[2].empty()))
        fail("face " + std::to_string(face_number_) + ": corner \"" + printable(corner) +
             "\" is not v, v/vt, v//vn or v/vt/vn");
      const int form = int(has_texture) + 2 * int(has_normal);
      if (first_form < 0) first_form = form;
      if (form != first_form)
        fail("face " + std::to_string(face_number_) + ": corner \"" + printable(corner) +
             "\" does not give the same indices as the first corner \"" + printable(tokens_[1]) + "\"");
      vertices_.push_back(index(lists_[kVertex], parts[0]));
      if (has_texture) face_texcoords_.push_back(index(lists_[kTexture], parts[1]));
      if (has_normal) face_normals_.push_back(index(lists_[kNormal], parts[2]));
    }
    all_normals_ = all_normals_ && !face_normals_.empty();
    all_texcoords_ = all_texcoords_ && !face_texcoords_.empty();
    mesh_.polygons_split += corners > 3;
    // A fan from the first corner: exact for the convex polygons OBJ files hold.
    for (size_t c = 1; c + 1 < corners; ++c) {
      mesh_.triangles.push_back({vertices_[0], vertices_[c], vertices_[c + 1]});
      mesh_.triangle_materials.push_back(material_);
      if (all_normals_) corner_normal_indices_.push_back({face_normals_[0], face_normals_[c], face_normals_[c + 1]});
      if (all_texcoords_) corner_texcoord_indices_.push_back({face_texcoords_[0], face_texcoords_[c], face_texcoords_[c + 1]});
    }
  }

  std::string_view text_;
  const std::filesystem::path& file_;
  size_t at_ = 0, line_number_ = 0, face_number_ = 0;
  IndexedList lists_[3] = {{"vertex index", "vertices"}, {"texture coordinate index", "texture coordinates"},
                           {"normal index", "normals"}};
  Mesh mesh_;
  std::vector<glm::vec3> normals_;
  bool all_normals_ = true;  // every face so far gives a normal at each corner
  std::vector<std::array<uint32_t, 3>> corner_normal_indices_;
  std::vector<glm::vec2> texcoords_;
  bool all_texcoords_ = true;  // and a texture coordinate
  std::vector<std::array<uint32_t, 3>> corner_texcoord_indices_;
  uint32_t material_ = Mesh::kNoMaterial;  // of the faces being read (usemtl)
  std::unordered_map<std::string, uint32_t> material_index_;  // Mesh::material_names -> its index
  // Scratch space for the line being read, kept to save allocations.
  std::vector<std::string_view> tokens_;
  std::vector<float> coordinates_;
  std::vector<uint32_t> vertices_, face_normals_, face_texcoords_;
};

}  // namespace

Mesh parse_obj(std::string_view text, const std::filesystem::path& file) { return ObjParser(text, file).parse(); }

}  // namespace vkray
