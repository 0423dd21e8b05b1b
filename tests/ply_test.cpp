// vkray's PLY reader: the three formats agree, what it skips, and every way a file can be wrong.
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "mesh/ply.h"

namespace vkray {
namespace {

const std::filesystem::path kDragon = std::filesystem::path(VKRAY_SCENE_DIR) / "meshes/stanford-dragon-100k.ply";

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// The message parse_ply throws for `bytes`, or "" when it reads them.
std::string ply_error(const std::string& bytes) {
  try {
    parse_ply(bytes, "test.ply");
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

const std::string kTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

// The dragon's layout: vertex {float x y z nx ny nz; int flags}, face {list uchar int; int flags}.
// (The loop over a face's corners also takes its trailing int flags.)
struct DragonLayout {
  size_t vertices = 50004, faces = 100002;
};

// The dragon rewritten in another format from its little-endian body, value by value.
std::string rewrite_dragon(const std::string& little_endian, const std::string& format) {
  const size_t body = little_endian.find("end_header\n") + 11;
  std::string header = little_endian.substr(0, body);
  header.replace(header.find("binary_little_endian"), 20, format);
  std::string out = header;
  const char* at = little_endian.data() + body;
  auto take = [&](size_t size) {
    std::string bytes(at, size);
    at += size;
    if (format == "binary_big_endian") std::reverse(bytes.begin(), bytes.end());
    return bytes;
  };
  auto text = [&](auto value) {
    std::memcpy(&value, at, sizeof value);
    at += sizeof value;
    if constexpr (std::is_floating_point_v<decltype(value)>) {
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "%.9g", double(value));  // round-trips a float
      return std::string(buffer);
    } else {
      return std::to_string(+value);
    }
  };
  const DragonLayout layout;
  const bool ascii = format == "ascii";
  for (size_t v = 0; v < layout.vertices; ++v) {
    for (int k = 0; k < 6; ++k) out.append(ascii ? text(float{}) : take(4)).append(ascii ? " " : "");
    out.append(ascii ? text(int32_t{}) : take(4)).append(ascii ? "\n" : "");
  }
  for (size_t f = 0; f < layout.faces; ++f) {
    const auto corners = static_cast<uint8_t>(*at);
    out.append(ascii ? text(uint8_t{}) : take(1));
    for (unsigned c = 0; c <= corners; ++c) out.append(ascii ? " " : "").append(ascii ? text(int32_t{}) : take(4));
    out.append(ascii ? "\n" : "");
  }
  return out;
}

TEST(PlyTest, TheThreeFormatsReadTheSameMesh) {
  const std::string little = read_file(kDragon);
  const Mesh expected = parse_ply(little, kDragon);
  ASSERT_EQ(expected.triangles.size(), 100002u);
  for (const std::string format : {"binary_big_endian", "ascii"}) {
    SCOPED_TRACE(format);
    const Mesh m = parse_ply(rewrite_dragon(little, format), "dragon.ply");
    ASSERT_EQ(m.positions.size(), expected.positions.size());
    ASSERT_EQ(m.triangles.size(), expected.triangles.size());
    EXPECT_EQ(m.positions, expected.positions);
    EXPECT_EQ(m.triangles, expected.triangles);
    EXPECT_EQ(m.corner_normals, expected.corner_normals);
  }
}

TEST(PlyTest, SkipsWhatItDoesNotUse) {
  // Properties before, between and after x y z, an extra element with a list, CRLF line ends,
  // a leading '+', the index list named vertex_index, and faces declared before vertices.
  const Mesh m = parse_ply(
      "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nelement face 2\r\nproperty list uchar uint vertex_index\r\n"
      "element edge 1\r\nproperty list int float weights\r\nproperty uchar flag\r\n"
      "element vertex 4\r\nproperty double red\r\nproperty float x\r\nproperty float y\r\nproperty short id\r\n"
      "property float z\r\nproperty list uchar int neighbours\r\nend_header\r\n"
      "3 0 1 2\r\n4 0 1 2 3\r\n2 0.5 0.25 7\r\n"
      "0.5 0 0 1 0 0\r\n0.5 1 0 2 +0 3 1 2 3\r\n0.5 1 1 3 0 0\r\n0.5 0 1 4 0e0 1 9\r\n",
      "hand.ply");
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[2], glm::vec3(1, 1, 0));
  EXPECT_EQ(m.triangles.size(), 3u);
  EXPECT_EQ(m.polygons_split, 1u);
  EXPECT_TRUE(m.corner_normals.empty());
}

// Three vertices, each with a list of doubles vkray does not use (0, 1 and 2 long), and one face.
std::string binary_with_lists() {
  std::string file =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property list uchar double extra\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](auto value) { file.append(reinterpret_cast<const char*>(&value), sizeof value); };
  const float corners[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int v = 0; v < 3; ++v) {
    for (const float c : corners[v]) put(c);
    put(uint8_t(v));
    for (int k = 0; k < v; ++k) put(double(k));
  }
  put(uint8_t(3));
  for (const int32_t i : {0, 1, 2}) put(i);
  return file;
}

TEST(PlyTest, BinaryListsOfOtherElementsAreSkippedWhole) {
  const Mesh m = parse_ply(binary_with_lists(), "lists.ply");
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.positions[2], glm::vec3(0, 1, 0));
}

TEST(PlyTest, EveryTruncationIsAnError) {
  const std::string file = binary_with_lists();
  for (size_t size = 0; size < file.size(); ++size) EXPECT_NE(ply_error(file.substr(0, size)), "") << size;
  EXPECT_NE(ply_error(file.substr(0, file.size() - 1)).find("test.ply: face 0: a list of 3 items runs past the end of the file"),
            std::string::npos);
}

TEST(PlyTest, ErrorsNameTheLineOrElement) {
  const std::pair<std::string, std::string> cases[] = {
      {"", "not a PLY file"},
      {"ply", "no end_header"},
      {"ply\nformat ascii 2.0\n", "test.ply:2: expected \"format"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "no end_header"},
      {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", "test.ply:3: a property before any element"},
      {"ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "test.ply:3: expected \"element NAME COUNT\""},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\nend_header\n", "test.ply:4: a list's length must have an integer type"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\nend_header\n", "test.ply:5: property \"x\" is declared twice"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nelement vertex 1\nend_header\n", "test.ply:4: element \"vertex\" is declared twice"},
      {"ply\nformat ascii 1.0\n\nend_header\n", "test.ply:3: an empty line"},
      {"ply\nformat ascii 1.0\nelement face 0\nend_header\n", "no vertex element"},
      {"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nend_header\n", "no \"z\" property"},
      {"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n", "no face element"},
      {"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\n"
       "property list uchar float vertex_indices\nend_header\n",
       "must be a list of integers"},
      {"ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
       "declares 9 vertex elements, more than the 6 bytes"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "test.ply:13: face 0: vertex index 3 out of range (the file has 3 vertices)"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "test.ply:13: face 0: vertex index -1 out of range"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "face 0: a face needs at least 3 vertices, this one has 2"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n", "test.ply:13: face 0: 300 does not fit the PLY type uchar"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n", "test.ply:13: face 0: \"2.5\" is not an integer"},
      {kTriangleHeader + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "test.ply:11: vertex 1: \"y\" is not a finite 32-bit number"},
      {kTriangleHeader + "0 0 0\n1 0 1e39\n0 1 0\n3 0 1 2\n", "test.ply:11: vertex 1: \"z\" is not a finite 32-bit number"},
      {kTriangleHeader + "0 0 0\n1 0 1e999\n0 1 0\n3 0 1 2\n", "test.ply:11: vertex 1: \"1e999\" is not a number"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n", "test.ply:12: vertex 2: \"zero\" is not a number"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "test.ply:13: face 0: a list of 3 items runs past the end of the file"},
      {kTriangleHeader + "0 0 0\n1 0 0\n0 1          \n", "test.ply:13: vertex 2: the file ends inside this element"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
       "property list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n-4 0 1 2\n",
       "face 0: a list has a negative length (-4)"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
       "property list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n",
       "face 0: a list of 2000000000 items runs past the end of the file"},
  };
  for (const auto& [bytes, expected] : cases) {
    const std::string message = ply_error(bytes);
    EXPECT_NE(message.find(expected), std::string::npos) << "expected \"" << expected << "\" in \"" << message << "\"";
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace vkray
