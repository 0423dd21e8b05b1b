// Tangents for normal maps: MikkTSpace's on meshes whose files give none (their directions and
// signs in glTF's convention), a glTF file's own TANGENT turned with its node, and the scene-file
// keys that name a normal map.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "load/scene_loader.h"
#include "mesh/tangents.h"
#include "scene/scene.h"
#include "support/error_of.h"

namespace vkray {
namespace {

using test::error_of;

void expect_near(const glm::vec3& a, const glm::vec3& b, const std::string& what) {
  EXPECT_LT(glm::length(a - b), 1e-5f) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") against (" << b.x << ", " << b.y
                                       << ", " << b.z << ")";
}

// A unit quad in z = 0 facing +z, its texture coordinates (glTF's: v down the picture) given by `uv`
// at the corners (0, 0), (1, 0), (1, 1), (0, 1).
std::vector<TangentTriangle> quad(const std::array<glm::vec2, 4>& uv) {
  const glm::vec3 p[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const glm::vec3 n(0, 0, 1);
  return {TangentTriangle{{p[0], p[1], p[2]}, {n, n, n}, {uv[0], uv[1], uv[2]}},
          TangentTriangle{{p[0], p[2], p[3]}, {n, n, n}, {uv[0], uv[2], uv[3]}}};
}

TEST(MikkTSpaceTest, TangentRunsAlongUAndTheBitangentUpThePicture) {
  // The picture upright on the quad: u along +x, v down it (from y = 1 to y = 0).
  const auto tangents = mikktspace_tangents(quad({glm::vec2(0, 1), glm::vec2(1, 1), glm::vec2(1, 0), glm::vec2(0, 0)}));
  for (const auto& triangle : tangents)
    for (const glm::vec4& t : triangle) {
      expect_near(glm::vec3(t), glm::vec3(1, 0, 0), "tangent");
      EXPECT_EQ(t.w, 1.0f);  // w cross(n, t) = +y: up the picture, where v falls
    }
}

TEST(MikkTSpaceTest, AMirroredPictureTurnsTheSign) {
  // u along -x: the tangent turns, and the bitangent still points up the picture, so w is -1.
  const auto tangents = mikktspace_tangents(quad({glm::vec2(1, 1), glm::vec2(0, 1), glm::vec2(0, 0), glm::vec2(1, 0)}));
  for (const auto& triangle : tangents)
    for (const glm::vec4& t : triangle) {
      expect_near(glm::vec3(t), glm::vec3(-1, 0, 0), "tangent");
      EXPECT_EQ(t.w, -1.0f);
      expect_near(t.w * glm::cross(glm::vec3(0, 0, 1), glm::vec3(t)), glm::vec3(0, 1, 0), "bitangent");
    }
}

TEST(MikkTSpaceTest, ARotatedPictureTurnsTheTangent) {
  // The picture turned a quarter: u grows along -y and v falls along +x.
  const auto tangents = mikktspace_tangents(quad({glm::vec2(1, 1), glm::vec2(1, 0), glm::vec2(0, 0), glm::vec2(0, 1)}));
  for (const auto& triangle : tangents)
    for (const glm::vec4& t : triangle) {
      expect_near(glm::vec3(t), glm::vec3(0, -1, 0), "tangent");
      expect_near(t.w * glm::cross(glm::vec3(0, 0, 1), glm::vec3(t)), glm::vec3(1, 0, 0), "bitangent");
    }
}

const std::filesystem::path kChecks = VKRAY_CHECK_DIR;

// A scene file whose one material, `material` (JSON), covers the tiled floor (y = 0, facing +y; its
// picture's top toward -z), with `transform`.
Scene floor_scene(const std::string& material, const std::string& transform = "{}") {
  return parse_scene(R"({"camera": {"position": [0, 5, 5], "look_at": [0, 0, 0], "vertical_fov": 40},
                         "materials": {"m": )" + material + R"(},
                         "objects": [{"type": "mesh", "file": "../scenes/meshes/tiled-floor.obj", "material": "m",
                                      "transform": )" + transform + "}]}",
                     kChecks / "floor.json");
}

TEST(NormalMapSceneTest, AMeshFileGetsMikkTSpaceTangentsWhereItsMaterialHasANormalMap) {
  const Scene scene = floor_scene(R"({"albedo": [0.5, 0.5, 0.5], "normal_texture": "textures/bumps-normal.png", "normal_scale": 0.5})");
  ASSERT_EQ(scene.triangles.size(), 2u);
  EXPECT_TRUE(scene.materials[0].normal_texture.present());
  EXPECT_EQ(scene.materials[0].normal_scale, 0.5f);
  for (const Triangle& t : scene.triangles)
    for (const glm::vec4& tangent : t.tangents) {
      expect_near(glm::vec3(tangent), glm::vec3(1, 0, 0), "tangent");
      expect_near(tangent.w * glm::cross(glm::vec3(0, 1, 0), glm::vec3(tangent)), glm::vec3(0, 0, -1), "bitangent");
    }
}

TEST(NormalMapSceneTest, TangentsAreMadeInWorldSpaceAfterTheTransform) {
  // Mirrored along x: u now grows along -x, up the picture is still -z, and the winding's normal
  // (which a flat triangle is shaded with) still points up: a mirror keeps front faces front (the
  // corners are taken the other way round), so the bitangent's sign turns instead.
  const Scene scene = floor_scene(R"({"albedo": [0.5, 0.5, 0.5], "normal_texture": "textures/bumps-normal.png"})", R"({"scale": [-1, 1, 1]})");
  for (const Triangle& t : scene.triangles) {
    const glm::vec3 n = glm::normalize(glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0]));
    expect_near(n, glm::vec3(0, 1, 0), "normal");
    for (const glm::vec4& tangent : t.tangents) {
      expect_near(glm::vec3(tangent), glm::vec3(-1, 0, 0), "tangent");
      expect_near(tangent.w * glm::cross(n, glm::vec3(tangent)), glm::vec3(0, 0, -1), "bitangent");
    }
  }
}

TEST(NormalMapSceneTest, NoNormalMapNoTangents) {
  const Scene scene = floor_scene(R"({"albedo": [0.5, 0.5, 0.5]})");
  for (const Triangle& t : scene.triangles) EXPECT_FALSE(t.has_tangents());
}

TEST(NormalMapSceneTest, NormalScaleNeedsANormalTexture) {
  EXPECT_NE(error_of([] { floor_scene(R"({"albedo": [0.5, 0.5, 0.5], "normal_scale": 2})"); })
                .find("/materials/m/normal_scale: normal_scale without a normal_texture"),
            std::string::npos);
}

// NormalTangentMirrorTest brings its own TANGENT, with both signs (its mirrored test cells).
TEST(NormalMapSceneTest, AGltfFilesTangentsAreReadAndTurnWithItsNode) {
  const std::filesystem::path file = std::filesystem::path(VKRAY_SCENE_DIR) / "gltf/NormalTangentMirrorTest/glTF/NormalTangentMirrorTest.gltf";
  const auto load = [&](const std::string& transform) {
    return parse_scene(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "vertical_fov": 40},
                           "objects": [{"type": "gltf", "file": ")" + file.string() + R"(", "transform": )" + transform + "}]}",
                       kChecks / "mirror.json");
  };
  const Scene plain = load("{}"), mirrored = load(R"({"scale": [-1, 1, 1]})");
  ASSERT_EQ(plain.triangles.size(), mirrored.triangles.size());
  size_t positive = 0, negative = 0;
  for (size_t i = 0; i < plain.triangles.size(); ++i) {
    const Triangle &a = plain.triangles[i], &b = mirrored.triangles[i];
    if (!a.has_tangents()) continue;
    positive += a.tangents[0].w > 0, negative += a.tangents[0].w < 0;
    // The mirror swaps two corners to keep the winding's front; each corner keeps its tangent.
    for (size_t k = 0; k < 3; ++k) {
      const size_t m = k == 0 ? 0 : 3 - k;
      EXPECT_NEAR(glm::length(glm::vec3(a.tangents[k])), 1.0f, 1e-5f);
      expect_near(glm::vec3(b.tangents[m]), glm::vec3(-a.tangents[k].x, a.tangents[k].y, a.tangents[k].z), "mirrored tangent");
      EXPECT_EQ(b.tangents[m].w, -a.tangents[k].w);
    }
  }
  EXPECT_GT(positive, 100u);
  EXPECT_GT(negative, 20u);
}

}  // namespace
}  // namespace vkray
