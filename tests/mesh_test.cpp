// Mesh files: the real test meshes, triangulation, smooth normals, and every way a file can be wrong.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "load/mesh_file.h"
#include "mesh/normals.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "support/temp_dir.h"

namespace vkray {
namespace {

const std::filesystem::path kMeshes = std::filesystem::path(VKRAY_SCENE_DIR) / "meshes";

// load_mesh(file) throws a MeshError that names the file and contains `what`.
void expect_mesh_error(const std::filesystem::path& file, const std::string& what) {
  try {
    load_mesh(file);
    ADD_FAILURE() << "no error for " << file;
  } catch (const MeshError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << "expected \"" << what << "\" in: " << message;
  }
}

TEST(MeshTest, LoadsTheTestMeshes) {
  const Mesh bunny = load_mesh(kMeshes / "stanford-bunny.obj");
  EXPECT_EQ(bunny.triangles.size(), 69451u);
  EXPECT_EQ(bunny.positions.size(), 35947u);
  EXPECT_TRUE(bunny.corner_normals.empty());
  const Mesh dragon = load_mesh(kMeshes / "stanford-dragon-100k.ply");  // binary PLY with normals
  EXPECT_EQ(dragon.triangles.size(), 100002u);
  EXPECT_EQ(dragon.positions.size(), 50004u);
  EXPECT_EQ(dragon.corner_normals.size(), 100002u);
  EXPECT_NEAR(glm::length(dragon.corner_normals[500][1]), 1.0f, 1e-3f);
  EXPECT_EQ(load_mesh(kMeshes / "teapot.obj").triangles.size(), 6320u);
}

class MeshFileTest : public ::testing::Test {
 protected:
  std::filesystem::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  test::TempDir dir_;
};

TEST_F(MeshFileTest, PolygonsAreSplitIntoTriangles) {
  const Mesh m = load_mesh(write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 4\nf 2 5 3\n"));
  EXPECT_EQ(m.triangles.size(), 3u);
  EXPECT_EQ(m.polygons_split, 1u);
}

TEST_F(MeshFileTest, AsciiPlyWithAQuad) {
  const Mesh m = load_mesh(write("quad.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                 "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                 "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"));
  EXPECT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.positions.size(), 4u);
}

TEST_F(MeshFileTest, ObjNormalsArePerCorner) {
  const Mesh m = load_mesh(write("n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\nf 1//1 2//2 3//1\n"));
  ASSERT_EQ(m.corner_normals.size(), 1u);
  EXPECT_EQ(m.corner_normals[0][1], glm::vec3(0, 1, 0));
}

TEST_F(MeshFileTest, Errors) {
  expect_mesh_error(dir_ / "missing.obj", "not found");
  std::filesystem::create_directory(dir_ / "folder.obj");
  expect_mesh_error(dir_ / "folder.obj", "is a directory");
  expect_mesh_error(write("mesh.stl", "solid x\n"), "unknown mesh format \".stl\"");
  expect_mesh_error(write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n"), "range.obj:5: face 2: vertex index 9 is out of range");
  expect_mesh_error(write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "nan.obj:2: vertex coordinate \"nan\"");
  expect_mesh_error(write("word.obj", "v 0 0 0\nv 1 0 0\nv 0 abc 0\nf 1 2 3\n"), "word.obj:3:");
  expect_mesh_error(write("huge.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"), "huge.obj:2:");
  expect_mesh_error(write("short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"), "short.obj:2:");
  expect_mesh_error(write("empty.obj", "# nothing\n"), "no faces");
  expect_mesh_error(write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "zero.obj");
  expect_mesh_error(write("range.ply",
                          "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                    "range.ply");
  // A binary PLY cut off in the middle of its faces.
  std::ifstream in(kMeshes / "stanford-dragon-100k.ply", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  expect_mesh_error(write("cut.ply", bytes.substr(0, bytes.size() / 2)), "cut.ply");
  expect_mesh_error(write("garbage.ply", std::string("ply\n\x01\x02\xff garbage", 15)), "garbage.ply");
}

// The fan of a convex polygon covers it exactly: its triangles' areas add up to the polygon's.
TEST_F(MeshFileTest, AFaceOfThreeHundredCornersIsSplitIntoAFanCoveringIt) {
  constexpr int kCorners = 300;
  const double pi = std::acos(-1.0);
  std::string text, face = "f";
  for (int i = 0; i < kCorners; ++i) {
    const double a = 2 * pi * i / kCorners;
    char vertex[64];
    std::snprintf(vertex, sizeof vertex, "v %.9f %.9f 0\n", std::cos(a), std::sin(a));
    text += vertex;
    face += ' ';
    face += std::to_string(i + 1);
  }
  // A triangle after the polygon, so that a miscounted polygon would shift it.
  text += face + "\nv 5 5 5\nv 6 5 5\nv 5 6 5\nf -3 -2 -1\n";
  const Mesh m = load_mesh(write("polygon.obj", text));
  ASSERT_EQ(m.triangles.size(), size_t(kCorners - 2 + 1));
  EXPECT_EQ(m.polygons_split, 1u);
  double area = 0;
  for (size_t t = 0; t + 1 < m.triangles.size(); ++t) {
    const auto& tri = m.triangles[t];
    EXPECT_EQ(tri[0], 0u);
    area += 0.5 * glm::length(glm::cross(m.positions[tri[1]] - m.positions[tri[0]], m.positions[tri[2]] - m.positions[tri[0]]));
  }
  EXPECT_NEAR(area, 0.5 * kCorners * std::sin(2 * pi / kCorners), 1e-4);
  EXPECT_EQ(m.triangles.back(), (std::array<uint32_t, 3>{kCorners, kCorners + 1, kCorners + 2}));
}

// "\r\n", "\n" and a lone "\r" (old Mac files) each end one line, for every kind of line.
TEST_F(MeshFileTest, EveryLineEndingEndsALine) {
  for (const std::string end : {"\n", "\r\n", "\r"}) {
    const Mesh m = load_mesh(write("good.obj", "v 0 0 0" + end + "v 1 0 0" + end + "v 0 1 0" + end + "vn 0 0 1" + end +
                                                   "f 1//1 2//1 3//1" + end));
    EXPECT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.corner_normals.size(), 1u);
    expect_mesh_error(write("coordinate.obj", "v 0 0 0" + end + "v 1 0 0" + end + "v 0 abc 0" + end + "f 1 2 3" + end),
                      "coordinate.obj:3: vertex coordinate \"abc\"");
    expect_mesh_error(write("index.obj", "v 0 0 0" + end + "v 1 0 0" + end + "v 0 1 0" + end + "f 1 2 x" + end),
                      "index.obj:4: face 1: vertex index \"x\" is not an integer");
    expect_mesh_error(write("normal.obj", "v 0 0 0" + end + "vn 0 zero 1" + end + "f 1 1 1" + end), "normal.obj:2: normal");
  }
}

TEST_F(MeshFileTest, EveryFaceIndexIsChecked) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const auto error = [&](const std::string& face, const std::string& what) {
    expect_mesh_error(write("f.obj", v + "vt 0 0\nvn 0 0 1\n" + face + "\n"), "f.obj:6: face 1: " + what);
  };
  error("f 1 2 99999999999999999999", "vertex index 99999999999999999999 is out of range (the file has 3 vertices)");
  error("f 1 2 -99999999999999999999", "vertex index -99999999999999999999 is out of range");
  error("f 1 2 4294967298", "vertex index 4294967298 is out of range");
  error("f 1 2 4", "vertex index 4 is out of range (the file has 3 vertices)");
  error("f 1 2 -4", "vertex index -4 is out of range");
  error("f 1 2 0", "vertex index 0 is out of range");
  error("f 1 2 3x", "vertex index \"3x\" is not an integer");
  error("f 1 2 +3", "vertex index \"+3\" is not an integer");
  error("f 1 2 3.0", "vertex index \"3.0\" is not an integer");
  error("f 1//1 2//1 3//2", "normal index 2 is out of range (the file has 1 normals)");
  error("f 1/1 2/1 3/99999999999", "texture coordinate index 99999999999 is out of range");
  error("f 1/ 2/ 3/", "corner \"1/\"");
  error("f 1//1 2//1 3//", "corner \"3//\"");
  error("f 1/1/1/1 2 3", "corner \"1/1/1/1\"");
  error("f 1/1 2//1 3", "corner \"2//1\" does not give the same indices as the first corner \"1/1\"");
  error("f 1 2", "2 corners, a face needs at least 3");
  // Relative indices count back from the last vertex read so far, not from the file's end.
  const Mesh m = load_mesh(write("rel.obj", v + "f -3 -2 -1\nv 2 2 2\nf -4 -3 -2\n"));
  EXPECT_EQ(m.triangles[0], m.triangles[1]);
  // A face may use vertices defined after it.
  EXPECT_EQ(load_mesh(write("ahead.obj", "f 1 2 3\n" + v)).triangles.size(), 1u);
}

TEST_F(MeshFileTest, NormalsAndTextureCoordinatesAreNumbers) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expect_mesh_error(write("vn.obj", v + "vn 0 0 nan\nf 1//1 2//1 3//1\n"), "vn.obj:4: normal coordinate \"nan\"");
  expect_mesh_error(write("vn2.obj", v + "vn 0 1\nf 1//1 2//1 3//1\n"), "vn2.obj:4:");
  expect_mesh_error(write("vt.obj", v + "vt 0 u\nf 1/1 2/1 3/1\n"), "vt.obj:4: texture coordinate \"u\"");
  expect_mesh_error(write("v.obj", v + "v 1 2 3 garbage\nf 1 2 3\n"), "v.obj:4: vertex coordinate \"garbage\"");
  // Extra numbers (w, or a colour) and comments are allowed.
  EXPECT_EQ(load_mesh(write("extra.obj", "v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0  # a comment\n# f 9 9 9\nf 1 2 3\n"))
                .triangles.size(),
            1u);
}

TEST(MeshTest, InputsTheFuzzerFoundAreRefused) {
  // Each of these crashed or corrupted memory inside assimp, which read PLY files before vkray's
  // own reader did (tests/bad-inputs/meshes/fuzz-*). Each is malformed and must be refused.
  size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(VKRAY_TEST_DIR) / "bad-inputs/meshes")) {
    if (entry.path().filename().string().rfind("fuzz-", 0) != 0) continue;
    ++files;
    EXPECT_THROW(load_mesh(entry.path()), MeshError) << entry.path();
  }
  EXPECT_GE(files, 4u);
}

TEST(SmoothNormalsTest, AreaWeightedAndWelded) {
  // Two triangles of a tent, the second with its shared vertices duplicated (not welded), as in the teapot.
  const glm::vec3 a(0, 0, 0), b(0, 0, 1), c(1, 1, 0.5f), d(-1, 1, 0.5f);
  const auto normals = area_weighted_normals({{{a, b, c}}, {{b, a, d}}});
  // The shared edge a-b gets the average of the two faces' normals: straight up (+y), in both triangles.
  for (const glm::vec3& n : {normals[0][0], normals[0][1], normals[1][0], normals[1][1]}) {
    EXPECT_NEAR(n.x, 0.0f, 1e-6f);
    EXPECT_NEAR(n.y, 1.0f, 1e-6f);
  }
  EXPECT_NEAR(glm::length(normals[0][2]), 1.0f, 1e-6f);
}

TEST_F(MeshFileTest, SceneMeshObjects) {
  write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
  std::filesystem::create_directory(dir_ / "scenes");
  write("scenes/s.json", R"({"camera": {"position": [0, 0, -5], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": "../tri.obj", "material": "m", "transform": {"translate": [0, 0, 2]}},
                {"type": "mesh", "file": "../tri.obj", "material": "m", "smooth": true, "transform": {"rotate": [90, 0, 0]}}]})");
  const Scene scene = load_scene(dir_ / "scenes/s.json");
  ASSERT_EQ(scene.triangles.size(), 4u);
  EXPECT_EQ(scene.triangles[0].v[0], glm::vec3(0, 0, 2));
  EXPECT_FALSE(scene.triangles[0].smooth);
  ASSERT_TRUE(scene.triangles[2].smooth);
  // The flat square's normal is -z (or +z); rotated 90 degrees about x it becomes -+y.
  EXPECT_NEAR(std::abs(scene.triangles[2].normals[0].y), 1.0f, 1e-5f);
  ASSERT_EQ(scene.referenced_files.size(), 1u);  // loaded once, used twice
  EXPECT_EQ(scene.referenced_files[0], (dir_ / "tri.obj").lexically_normal());
}

// Policy (docs/limits.md): a mesh path may leave the scene's folder, by ".." or as
// an absolute path, as a shared mesh library needs; vkray only reads what it names, and only a
// regular file of bounded size.
TEST_F(MeshFileTest, MeshPathsMayLeaveTheSceneFolder) {
  std::filesystem::create_directory(dir_ / "library");
  write("library/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  std::filesystem::create_directory(dir_ / "scenes");
  write("scenes/s.json", R"({"camera": {"position": [0, 0, -5], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": ")" + (dir_ / "library/tri.obj").string() + R"(", "material": "m"},
                {"type": "mesh", "file": "../library/tri.obj", "material": "m"},
                {"type": "mesh", "file": "/dev/zero", "material": "m"}]})");
  try {
    load_scene(dir_ / "scenes/s.json");
    ADD_FAILURE() << "/dev/zero was read as a mesh";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("/objects/2/file: /dev/zero: is a character device"), std::string::npos) << e.what();
  }
  write("scenes/s.json", R"({"camera": {"position": [0, 0, -5], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": ")" + (dir_ / "library/tri.obj").string() + R"(", "material": "m"},
                {"type": "mesh", "file": "../library/tri.obj", "material": "m"}]})");
  const Scene scene = load_scene(dir_ / "scenes/s.json");
  EXPECT_EQ(scene.triangles.size(), 2u);
  ASSERT_EQ(scene.referenced_files.size(), 1u);  // the same file by either path
}

TEST_F(MeshFileTest, SceneMeshErrorsNameTheKeyAndTheMeshProblem) {
  write("bad.obj", "v 0 0 0\nf 1 2 3\n");
  write("s.json", R"({"camera": {"position": [0, 0, -5], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": "bad.obj", "material": "m"}]})");
  try {
    load_scene(dir_ / "s.json");
    ADD_FAILURE() << "no error";
  } catch (const MeshError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("s.json: /objects/0/file: "), std::string::npos) << m;
    EXPECT_NE(m.find("bad.obj:2: face 1"), std::string::npos) << m;
  }
  write("s2.json", R"({"camera": {"position": [0, 0, -5], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": "bad.obj", "material": "m", "smooth": "yes"}]})");
  EXPECT_THROW(load_scene(dir_ / "s2.json"), SceneError);
}

}  // namespace
}  // namespace vkray
