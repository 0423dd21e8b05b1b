#include "mesh/mtl.h"

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include "base/errors.h"

namespace vkray {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

// The options a map statement may give before its file name, with how many values each takes
// (at most; -s, -o and -t take one to three).
const std::map<std::string_view, int>& map_options() {
  static const std::map<std::string_view, int> options = {
      {"-blendu", 1}, {"-blendv", 1}, {"-bm", 1}, {"-boost", 1}, {"-cc", 1}, {"-clamp", 1}, {"-imfchan", 1},
      {"-mm", 2},     {"-o", 3},      {"-s", 3},  {"-t", 3},     {"-texres", 1}, {"-type", 1}};
  return options;
}

class MtlParser {
 public:
  MtlParser(std::string_view text, const std::filesystem::path& file) : text_(text), file_(file) {}

  MtlLibrary parse() {
    for (size_t at = 0; at < text_.size();) {
      size_t end = at;
      while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
      std::string_view line = text_.substr(at, end - at);
      at = end + (end + 1 < text_.size() && text_[end] == '\r' && text_[end + 1] == '\n' ? 2 : 1);
      ++line_;
      if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      line = trim(line);
      if (line.empty()) continue;
      size_t split = 0;
      while (split < line.size() && !is_space(line[split])) ++split;
      const std::string_view keyword = line.substr(0, split), rest = trim(line.substr(split));
      statement(keyword, rest);
    }
    finish_material();
    return std::move(library_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw MeshError(file_.string() + ":" + std::to_string(line_) + ": " + what);
  }
  void warn_once(const std::string& what) {
    if (warned_.insert(what).second) library_.warnings.push_back(printable(file_.string() + ":" + std::to_string(line_) + ": " + what, 300));
  }

  MtlMaterial& current(std::string_view keyword) {
    if (!open_) fail(std::string(keyword) + " before the first newmtl");
    return material_;
  }

  void statement(std::string_view keyword, std::string_view rest) {
    if (keyword == "newmtl") {
      finish_material();
      if (rest.empty()) fail("newmtl without a material name");
      material_ = MtlMaterial();
      material_.name = std::string(rest);
      open_ = true;
      kd_given_ = d_given_ = false;
    } else if (keyword == "Kd") {
      current(keyword).diffuse = colour(keyword, rest);
      kd_given_ = true;
    } else if (keyword == "Ke") {
      current(keyword).emission = colour(keyword, rest);
    } else if (keyword == "map_Kd") {
      current(keyword).diffuse_map = texture(keyword, rest);
    } else if (keyword == "map_Ke") {
      current(keyword).emission_map = texture(keyword, rest);
    } else if (keyword == "d" || keyword == "Tr") {
      // The dissolve d, or Tr = 1 - d; where a material gives both, d.
      if (rest.starts_with("-halo")) {
        warn_once(std::string(keyword) + " -halo: not rendered (the dissolve is the same at every angle)");
        rest = trim(rest.substr(5));
      }
      double value = 0;
      const auto [ptr, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), value);
      if (ec != std::errc() || ptr != rest.data() + rest.size() || !(value >= 0.0 && value <= 1.0))
        fail(std::string(keyword) + ": expected a number from 0 to 1, got \"" + printable(rest) + "\"");
      MtlMaterial& m = current(keyword);
      if (keyword == "d") {
        m.opacity = float(value);
        d_given_ = true;
      } else if (!d_given_) {
        m.opacity = float(1.0 - value);
      }
    } else if (keyword == "map_d") {
      current(keyword).opacity_map = texture(keyword, rest);
    } else if (keyword.starts_with("map_") || keyword == "bump" || keyword == "disp" || keyword == "decal" || keyword == "norm" ||
               keyword == "refl") {
      warn_once(std::string(keyword) + ": not rendered (vkray renders map_Kd, map_Ke and map_d)");
    }
    // Ka, Ks, Ns, Ni, illum, Tf and others describe shading vkray does not do: a diffuse surface is.
  }

  void finish_material() {
    if (!open_) return;
    if (!kd_given_ && !material_.diffuse_map.file.empty()) material_.diffuse = glm::vec3(1.0f);
    library_.materials.push_back(std::move(material_));
    open_ = false;
  }

  glm::vec3 colour(std::string_view keyword, std::string_view rest) const {
    if (rest.starts_with("spectral") || rest.starts_with("xyz")) fail(std::string(keyword) + ": only r g b colours are read");
    float values[3];
    int count = 0;
    for (std::string_view r = rest; !r.empty(); r = trim(r)) {
      size_t end = 0;
      while (end < r.size() && !is_space(r[end])) ++end;
      double v = 0;
      const auto [ptr, ec] = std::from_chars(r.data(), r.data() + end, v);
      if (ec != std::errc() || ptr != r.data() + end || !std::isfinite(v) || std::abs(v) > FLT_MAX || v < 0 || count == 3)
        fail(std::string(keyword) + ": expected 1 or 3 non-negative numbers, got \"" + printable(rest) + "\"");
      values[count++] = float(v);
      r = r.substr(end);
    }
    if (count == 1) return glm::vec3(values[0]);  // one value: grey
    if (count != 3) fail(std::string(keyword) + ": expected 1 or 3 non-negative numbers, got \"" + printable(rest) + "\"");
    return {values[0], values[1], values[2]};
  }

  // "[-option values...]... file name": the options are skipped (but -clamp), the rest is the name.
  MtlTexture texture(std::string_view keyword, std::string_view rest) {
    MtlTexture t;
    while (rest.starts_with("-")) {
      size_t end = 0;
      while (end < rest.size() && !is_space(rest[end])) ++end;
      const std::string_view option = rest.substr(0, end);
      rest = trim(rest.substr(end));
      const auto known = map_options().find(option);
      if (known == map_options().end()) break;  // a file name that starts with '-'
      if (option == "-o" || option == "-s" || option == "-t")
        warn_once(std::string(keyword) + " " + std::string(option) + ": texture offsets, scales and turbulence are not rendered");
      for (int v = 0; v < known->second && !rest.empty(); ++v) {
        size_t value_end = 0;
        while (value_end < rest.size() && !is_space(rest[value_end])) ++value_end;
        const std::string_view value = rest.substr(0, value_end);
        double number = 0;
        const bool numeric = std::from_chars(value.data(), value.data() + value.size(), number).ec == std::errc();
        if (v > 0 && !numeric) break;  // -s 2: one value of up to three
        if (option == "-clamp") t.wrap = value == "on" ? TextureWrap::clamp_to_edge : TextureWrap::repeat;
        rest = trim(rest.substr(value_end));
      }
    }
    if (rest.empty()) fail(std::string(keyword) + " without a file name");
    t.file = std::filesystem::path(std::string(rest));
    return t;
  }

  std::string_view text_;
  const std::filesystem::path& file_;
  size_t line_ = 0;
  MtlLibrary library_;
  MtlMaterial material_;
  bool open_ = false, kd_given_ = false, d_given_ = false;
  std::set<std::string> warned_;
};

}  // namespace

MtlLibrary parse_mtl(std::string_view text, const std::filesystem::path& file) { return MtlParser(text, file).parse(); }

}  // namespace vkray
