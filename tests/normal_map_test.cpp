// Normal maps, rendered: the shading a tilted normal map gives a plane, worked out here from the
// contract (physics that needs no other renderer), on both renderers; proof that parity catches
// mistakes in the normal-map and shading-normal code; and the Khronos models that test tangents.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "support/test_assets.h"

namespace vkray::test {
namespace {

// ---- Physics: a plane whose normal map tilts it ------------------------------------------------------

class NormalMapShadingTest : public GpuTest {};

TEST_F(NormalMapShadingTest, AConstantMapShadesThePlaneAsItsTiltedNormalWould) {
  // The tiled floor (y = 0; u along +x, up its picture toward -z) with a white Lambertian material and
  // a normal map of one texel value: the normal (sin a, 0, cos a) along the tangent, or (0, sin a,
  // cos a) along the bitangent. Seen from above through a narrow camera at the origin, lit by one
  // point light at distance r in direction l: L = (albedo / pi) I (n . l) / r^2, n the map's normal
  // in the world: tangent +x, bitangent -z, normal +y.
  const double pi = 3.14159265358979323846, tilt = 0.5;
  TempDir dir;
  struct Case {
    glm::dvec3 tangent_space;
    glm::dvec3 light;
  };
  const double s = std::sin(tilt), c = std::cos(tilt);
  for (const Case& k : {Case{{s, 0, c}, {1.5, 1.5, 0}}, Case{{-s, 0, c}, {1.5, 1.5, 0}}, Case{{0, s, c}, {0, 1.5, -1.5}},
                        Case{{0, -s, c}, {0, 1.5, -1.5}}}) {
    TestPicture map{1, 1, {}};
    for (int i = 0; i < 3; ++i) map.rgb.push_back(uint8_t(std::lround((k.tangent_space[i] + 1) / 2 * 255)));
    write_file(dir / "map.png", png_bytes(map));
    // The normal the renderers see: the 8-bit value's, normalized.
    glm::dvec3 m;
    for (int i = 0; i < 3; ++i) m[i] = 2 * (map.rgb[size_t(i)] / 255.0) - 1;
    const glm::dvec3 n = glm::normalize(m.x * glm::dvec3(1, 0, 0) + m.y * glm::dvec3(0, 0, -1) + m.z * glm::dvec3(0, 1, 0));
    const double intensity = 10, r2 = glm::dot(k.light, k.light);
    const double expected = 0.5 / pi * intensity * glm::dot(n, glm::normalize(k.light)) / r2;
    const std::string json = R"({
      "camera": {"position": [0, 3, 0.0001], "look_at": [0, 0, 0], "vertical_fov": 0.5},
      "materials": {"m": {"albedo": [0.5, 0.5, 0.5], "normal_texture": "map.png"}},
      "lights": [{"type": "point", "position": [)" + std::to_string(k.light.x) + ", " + std::to_string(k.light.y) + ", " +
                             std::to_string(k.light.z) + R"(], "intensity": [10, 10, 10]}],
      "objects": [{"type": "mesh", "file": ")" + (std::filesystem::path(VKRAY_SCENE_DIR) / "meshes/tiled-floor.obj").string() +
                             R"(", "material": "m"}]})";
    const Scene scene = parse_scene(json, dir / "tilted.json");
    for (const bool cpu : {false, true}) {
      const double got = image_mean(render(scene, {8, 8, 1}, {}, cpu)).g;
      EXPECT_NEAR(got, expected, 0.005 * expected) << (cpu ? "CPU" : "GPU") << ", tangent-space normal (" << k.tangent_space.x << ", "
                                                   << k.tangent_space.y << ", " << k.tangent_space.z << ")";
    }
  }
}

// ---- Parity catches mistakes in the normal-map code (checks/normal-map-*.json) ----------------------

class BrokenNormalMap : public BrokenShaderParityTest {
 protected:
  BrokenNormalMap(const std::string& file, const std::string& good, const std::string& bad) : BrokenShaderParityTest(file, good, bad) {}
  void expect_caught(const char* integrator) { expect_caught_on_check(std::string("normal-map-") + integrator); }
};

class NormalMapIgnored : public BrokenNormalMap {
 protected:
  NormalMapIgnored()
      : BrokenNormalMap("primitives.glsl", "s.shading_normal = normal_mapped(s.shading_normal,",
                        "s.shading_normal = s.shading_normal + 0.0 * normal_mapped(s.shading_normal,") {}
};
TEST_F(NormalMapIgnored, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class NormalMapGreenFlipped : public BrokenNormalMap {
 protected:
  // A map read as DirectX's convention (green down the picture): every dome lit from the wrong side.
  NormalMapGreenFlipped() : BrokenNormalMap("primitives.glsl", "vec3(scale, scale, 1.0)", "vec3(scale, -scale, 1.0)") {}
};
TEST_F(NormalMapGreenFlipped, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

class NormalScaleIgnored : public BrokenNormalMap {
 protected:
  NormalScaleIgnored() : BrokenNormalMap("primitives.glsl", "vec3(scale, scale, 1.0)", "vec3(1.0, 1.0, 1.0)") {}
};
TEST_F(NormalScaleIgnored, IsCaught) { expect_caught("direct"); }

class ShadingNormalNotBent : public BrokenNormalMap {
 protected:
  // Normals that face away from the viewer kept as they are: their reflections go into the surface.
  ShadingNormalNotBent()
      : BrokenNormalMap("shade.glsl", "if (2.0 * n_wo * n_ng - iz >= threshold) return n;", "return n;") {}
};
TEST_F(ShadingNormalNotBent, IsCaught) {
  expect_caught("direct");
  expect_caught("path");
}

// The bitangent's sign ignored: the mirrored cells of the Khronos model whose tangents are mirrored.
class TangentSignIgnored : public BrokenShaderParityTest {
 protected:
  TangentSignIgnored() : BrokenShaderParityTest("primitives.glsl", "vec3 bt = (sign < 0.0 ? -1.0 : 1.0) * cross(n, t);", "vec3 bt = cross(n, t);") {}
};
TEST_F(TangentSignIgnored, IsCaught) {
  const Scene scene =
      load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "gltf/NormalTangentMirrorTest/glTF/NormalTangentMirrorTest.gltf");
  const ParityResult r = run(scene, {128, 128, 1});
  EXPECT_FALSE(r.metrics.pass) << describe_metrics(r.metrics);
}

}  // namespace
}  // namespace vkray::test
