// Mesh files: the real test meshes, triangulation, smooth normals, and every way a file can be wrong.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "mesh/load.h"
#include "mesh/normals.h"
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
  expect_mesh_error(write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n"), "face 2: vertex index out of range");
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
    EXPECT_NE(m.find("bad.obj: face 1"), std::string::npos) << m;
  }
  write("s2.json", R"({"camera": {"position": [0, 0, -5], "direction": [0, 0, 1], "focal_length": 1},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "objects": [{"type": "mesh", "file": "bad.obj", "material": "m", "smooth": "yes"}]})");
  EXPECT_THROW(load_scene(dir_ / "s2.json"), SceneError);
}

}  // namespace
}  // namespace vkray
