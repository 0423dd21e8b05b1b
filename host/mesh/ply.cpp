#include "mesh/ply.h"

#include <algorithm>
#include <bit>
#include <cfloat>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"

namespace vkray {
namespace {

[[noreturn]] void fail(const std::string& where, const std::string& what) { throw MeshError(where + ": " + what); }

// ---- the header ------------------------------------------------------------------------------

enum class Type : uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct TypeInfo {
  std::string_view name;
  Type type;
  unsigned size;
};
constexpr TypeInfo kTypes[] = {
    {"char", Type::Int8, 1},     {"uchar", Type::UInt8, 1},   {"int8", Type::Int8, 1},       {"uint8", Type::UInt8, 1},
    {"short", Type::Int16, 2},   {"ushort", Type::UInt16, 2}, {"int16", Type::Int16, 2},     {"uint16", Type::UInt16, 2},
    {"int", Type::Int32, 4},     {"uint", Type::UInt32, 4},   {"int32", Type::Int32, 4},     {"uint32", Type::UInt32, 4},
    {"float", Type::Float32, 4}, {"float32", Type::Float32, 4}, {"double", Type::Float64, 8}, {"float64", Type::Float64, 8},
};

unsigned size_of(Type type) {
  for (const TypeInfo& t : kTypes)
    if (t.type == type) return t.size;
  return 0;
}
std::string_view name_of(Type type) {
  for (const TypeInfo& t : kTypes)
    if (t.type == type) return t.name;
  return "?";
}
bool is_integer(Type type) { return type != Type::Float32 && type != Type::Float64; }

struct Property {
  std::string name;
  Type type = Type::Float32;  // a list's item type
  bool is_list = false;
  Type count_type = Type::UInt8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;

  std::optional<size_t> find(std::string_view property) const {
    for (size_t i = 0; i < properties.size(); ++i)
      if (properties[i].name == property) return i;
    return std::nullopt;
  }
};

enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t body_offset = 0;  // the first byte after end_header's line
  size_t lines = 0;        // header lines: an ASCII body's line numbers go on from here
};

constexpr size_t kMaxHeaderBytes = 1 << 16;

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
    size_t end = at;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
    if (end > at) out.push_back(line.substr(at, end - at));
    at = end;
  }
  return out;
}

Header read_header(std::string_view bytes, const std::filesystem::path& file) {
  if (!bytes.starts_with("ply")) fail(file.string(), "not a PLY file (no \"ply\" on the first line)");
  Header header;
  size_t at = 0;
  std::string_view line;
  auto bad = [&](const std::string& what) { fail(file.string() + ":" + std::to_string(header.lines), what); };
  auto next = [&]() {
    const size_t end = bytes.find('\n', at);
    if (end == std::string_view::npos || end >= kMaxHeaderBytes)
      fail(file.string(), "the PLY header has no end_header line (in its first 64 KiB)");
    line = bytes.substr(at, end - at);
    at = end + 1;
    ++header.lines;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    // Header lines are text; a binary byte here means a damaged or hostile file.
    if (std::any_of(line.begin(), line.end(), [](char c) { return (c < 0x20 && c != '\t') || c >= 0x7f; }))
      bad("the PLY header has a non-printable byte: \"" + printable(line) + "\"");
  };
  auto check_name = [&](std::string_view name) {
    if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
        }))
      bad("bad PLY name \"" + printable(name) + "\"");
  };
  auto type = [&](std::string_view name) {
    for (const TypeInfo& t : kTypes)
      if (t.name == name) return t.type;
    bad("unknown PLY property type \"" + printable(name) + "\"");
    return Type::Float32;  // not reached: bad() throws
  };

  next();
  if (line != "ply") bad("expected \"ply\", got \"" + printable(line) + "\"");
  next();
  const std::vector<std::string_view> format = words(line);
  if (format.size() != 3 || format[0] != "format" || format[2] != "1.0" ||
      (format[1] != "ascii" && format[1] != "binary_little_endian" && format[1] != "binary_big_endian"))
    bad("expected \"format ascii|binary_little_endian|binary_big_endian 1.0\", got \"" + printable(line) + "\"");
  header.format = format[1] == "ascii"                  ? Format::Ascii
                  : format[1] == "binary_little_endian" ? Format::BinaryLittleEndian
                                                        : Format::BinaryBigEndian;
  for (;;) {
    next();
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) bad("an empty line in the PLY header");
    if (w[0] == "end_header") {
      if (w.size() != 1) bad("unexpected text after end_header");
      break;
    }
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "element") {
      if (w.size() != 3 || w[2].find_first_not_of("0123456789") != std::string_view::npos || w[2].size() > 18)
        bad("expected \"element NAME COUNT\", got \"" + printable(line) + "\"");
      check_name(w[1]);
      for (const Element& e : header.elements)
        if (e.name == w[1]) bad("element \"" + std::string(w[1]) + "\" is declared twice");
      Element element;
      element.name = w[1];
      std::from_chars(w[2].data(), w[2].data() + w[2].size(), element.count);  // at most 18 digits: fits
      header.elements.push_back(std::move(element));
    } else if (w[0] == "property") {
      if (header.elements.empty()) bad("a property before any element");
      Property property;
      if (w.size() == 5 && w[1] == "list") {
        property.is_list = true;
        property.count_type = type(w[2]);
        if (!is_integer(property.count_type)) bad("a list's length must have an integer type, not " + std::string(w[2]));
        property.type = type(w[3]);
        property.name = w[4];
      } else if (w.size() == 3 && w[1] != "list") {
        property.type = type(w[1]);
        property.name = w[2];
      } else {
        bad("expected \"property TYPE NAME\" or \"property list TYPE TYPE NAME\", got \"" + printable(line) + "\"");
      }
      check_name(property.name);
      Element& element = header.elements.back();
      if (element.find(property.name)) bad("property \"" + property.name + "\" is declared twice in element " + element.name);
      element.properties.push_back(std::move(property));
    } else {
      bad("unknown PLY header line \"" + printable(line) + "\"");
    }
  }
  header.body_offset = at;

  // A header that declares more elements than the file can hold is refused before anything is
  // allocated for them (a billion-face header would otherwise cost seconds and gigabytes). The
  // least an element takes: its binary sizes (a list at least its length), or in ASCII one
  // character and one separator per property.
  const uint64_t available = bytes.size() - at;
  uint64_t needed = 0;
  for (const Element& e : header.elements) {
    uint64_t least = 0;
    for (const Property& p : e.properties)
      least += header.format == Format::Ascii ? 2 : size_of(p.is_list ? p.count_type : p.type);
    least = std::max<uint64_t>(least, 1);
    if (e.count > available / least || needed > available - e.count * least)
      fail(file.string(), "the header declares " + std::to_string(e.count) + " " + e.name + " elements, more than the " +
                              std::to_string(available) + " bytes after the header can hold");
    needed += e.count * least;
  }
  return header;
}

// ---- the body --------------------------------------------------------------------------------

// Reads the values of one element after another, in any of the three formats. Every read is
// checked against the end of the file, and every error names the element (and, in ASCII, the line).
class BodyReader {
 public:
  BodyReader(std::string_view bytes, const Header& header, const std::filesystem::path& file)
      : bytes_(bytes), at_(header.body_offset), line_(header.lines + 1), format_(header.format), file_(file) {}

  void begin(const Element& element, uint64_t index) {
    element_ = &element;
    index_ = index;
  }

  [[noreturn]] void error(const std::string& what) const {
    std::string where = file_.string();
    if (format_ == Format::Ascii) where += ":" + std::to_string(line_);
    if (element_) where += ": " + element_->name + " " + std::to_string(index_);
    fail(where, what);
  }

  double value(Type type) { return format_ == Format::Ascii ? ascii_value(type) : binary_value(type); }

  // A list's length, checked against what is left of the file before anything is read for it.
  uint64_t list_length(Type count_type, Type item_type) {
    const double length = value(count_type);
    if (length < 0) error("a list has a negative length (" + std::to_string(int64_t(length)) + ")");
    const auto n = static_cast<uint64_t>(length);
    const uint64_t left = bytes_.size() - at_;
    const uint64_t least = format_ == Format::Ascii ? 2 : size_of(item_type);
    if (n > left / least) error("a list of " + std::to_string(n) + " items runs past the end of the file");
    return n;
  }

  void skip(Type type, uint64_t count) {
    if (format_ == Format::Ascii) {
      for (uint64_t i = 0; i < count; ++i) ascii_value(type);
    } else {
      at_ += count * size_of(type);  // list_length() checked that this stays inside the file
    }
  }

 private:
  double binary_value(Type type) {
    const unsigned size = size_of(type);
    if (bytes_.size() - at_ < size) error("the file ends inside this element");
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + at_, size);
    at_ += size;
    const bool big = format_ == Format::BinaryBigEndian;
    if (big != (std::endian::native == std::endian::big)) std::reverse(raw, raw + size);
    auto as = [&]<typename T>(T value) {
      std::memcpy(&value, raw, sizeof value);
      return static_cast<double>(value);
    };
    switch (type) {
      case Type::Int8: return as(int8_t{});
      case Type::UInt8: return as(uint8_t{});
      case Type::Int16: return as(int16_t{});
      case Type::UInt16: return as(uint16_t{});
      case Type::Int32: return as(int32_t{});
      case Type::UInt32: return as(uint32_t{});
      case Type::Float32: return as(float{});
      case Type::Float64: return as(double{});
    }
    return 0;
  }

  double ascii_value(Type type) {
    while (at_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[at_]))) line_ += bytes_[at_++] == '\n';
    size_t end = at_;
    while (end < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[end]))) ++end;
    const std::string_view token = bytes_.substr(at_, end - at_);
    if (token.empty()) error("the file ends inside this element");
    at_ = end;
    const char* first = token.data();
    const char* last = first + token.size();
    if (*first == '+') ++first;  // from_chars does not take a leading '+'
    if (is_integer(type)) {
      int64_t n = 0;
      const auto [ptr, ec] = std::from_chars(first, last, n);
      if (ec != std::errc() || ptr != last) error("\"" + printable(token) + "\" is not an integer");
      const auto [low, high] = range(type);
      if (n < low || n > high) error(std::string(token) + " does not fit the PLY type " + std::string(name_of(type)));
      return static_cast<double>(n);
    }
    double x = 0;
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (ec != std::errc() || ptr != last) error("\"" + printable(token) + "\" is not a number");
    return x;
  }

  static std::pair<int64_t, int64_t> range(Type type) {
    switch (type) {
      case Type::Int8: return {INT8_MIN, INT8_MAX};
      case Type::UInt8: return {0, UINT8_MAX};
      case Type::Int16: return {INT16_MIN, INT16_MAX};
      case Type::UInt16: return {0, UINT16_MAX};
      case Type::Int32: return {INT32_MIN, INT32_MAX};
      case Type::UInt32: return {0, UINT32_MAX};
      default: return {INT64_MIN, INT64_MAX};
    }
  }

  std::string_view bytes_;
  size_t at_;
  size_t line_;
  Format format_;
  const std::filesystem::path& file_;
  const Element* element_ = nullptr;
  uint64_t index_ = 0;
};

// Where the properties vkray uses sit in their elements.
struct Layout {
  const Element* vertex = nullptr;
  size_t position[3] = {};
  bool has_normals = false;  // nx, ny and nz are all scalar properties of the vertex
  size_t normal[3] = {};
  const Element* face = nullptr;
  size_t indices = 0;
};

Layout find_layout(const Header& header, const std::filesystem::path& file) {
  Layout layout;
  for (const Element& e : header.elements) {
    if (e.name == "vertex") layout.vertex = &e;
    if (e.name == "face") layout.face = &e;
  }
  if (!layout.vertex) fail(file.string(), "the PLY header declares no vertex element");
  const char* axes[3] = {"x", "y", "z"};
  const char* normal_axes[3] = {"nx", "ny", "nz"};
  for (int k = 0; k < 3; ++k) {
    const std::optional<size_t> p = layout.vertex->find(axes[k]);
    if (!p) fail(file.string(), std::string("the vertex element has no \"") + axes[k] + "\" property");
    if (layout.vertex->properties[*p].is_list) fail(file.string(), std::string("the vertex property \"") + axes[k] + "\" is a list");
    layout.position[k] = *p;
  }
  layout.has_normals = true;
  for (int k = 0; k < 3; ++k) {
    const std::optional<size_t> p = layout.vertex->find(normal_axes[k]);
    layout.has_normals = layout.has_normals && p && !layout.vertex->properties[*p].is_list;
    if (p) layout.normal[k] = *p;
  }
  if (!layout.face) fail(file.string(), "the PLY header declares no face element");
  std::optional<size_t> indices = layout.face->find("vertex_indices");
  if (!indices) indices = layout.face->find("vertex_index");
  if (!indices) fail(file.string(), "the face element has no vertex_indices property");
  const Property& p = layout.face->properties[*indices];
  if (!p.is_list || !is_integer(p.type))
    fail(file.string(), "the face property \"" + p.name + "\" must be a list of integers");
  layout.indices = *indices;
  return layout;
}

}  // namespace

Mesh parse_ply(std::string_view bytes, const std::filesystem::path& file) {
  const Header header = read_header(bytes, file);
  const Layout layout = find_layout(header, file);
  const uint64_t vertex_count = layout.vertex->count;
  const bool has_normals = layout.has_normals;

  Mesh mesh;
  std::vector<glm::vec3> normals;
  mesh.positions.reserve(vertex_count);  // read_header checked the count against the file's size
  if (has_normals) normals.reserve(vertex_count);
  std::vector<double> values;  // one element's scalar properties
  std::vector<uint32_t> polygon;
  BodyReader in(bytes, header, file);

  for (const Element& element : header.elements) {
    values.assign(element.properties.size(), 0.0);
    for (uint64_t index = 0; index < element.count; ++index) {
      if (index % 4096 == 0) throw_if_interrupted();
      in.begin(element, index);
      polygon.clear();
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.is_list) {
          values[p] = in.value(property.type);
          continue;
        }
        const uint64_t length = in.list_length(property.count_type, property.type);
        if (&element != layout.face || p != layout.indices) {
          in.skip(property.type, length);
          continue;
        }
        if (length < 3) in.error("a face needs at least 3 vertices, this one has " + std::to_string(length));
        for (uint64_t c = 0; c < length; ++c) {
          const double v = in.value(property.type);
          if (v < 0 || v >= double(vertex_count))
            in.error("vertex index " + std::to_string(int64_t(v)) + " out of range (the file has " +
                     std::to_string(vertex_count) + " vertices)");
          polygon.push_back(static_cast<uint32_t>(v));
        }
      }

      if (&element == layout.vertex) {
        // Checked before the conversion: a double beyond float's range does not convert.
        auto coordinate = [&](size_t p) {
          const double v = values[p];
          if (!std::isfinite(v) || std::abs(v) > FLT_MAX)
            in.error("\"" + element.properties[p].name + "\" is not a finite 32-bit number");
          return static_cast<float>(v);
        };
        mesh.positions.emplace_back(coordinate(layout.position[0]), coordinate(layout.position[1]),
                                    coordinate(layout.position[2]));
        if (has_normals)
          normals.emplace_back(coordinate(layout.normal[0]), coordinate(layout.normal[1]), coordinate(layout.normal[2]));
      } else if (&element == layout.face) {
        mesh.polygons_split += polygon.size() > 3;
        // A fan from the first corner: exact for the convex polygons PLY files hold.
        for (size_t c = 1; c + 1 < polygon.size(); ++c) mesh.triangles.push_back({polygon[0], polygon[c], polygon[c + 1]});
      }
    }
  }

  if (has_normals) {
    mesh.corner_normals.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles) mesh.corner_normals.push_back({normals[t[0]], normals[t[1]], normals[t[2]]});
  }
  return mesh;
}

}  // namespace vkray
