// The lighting as the shader reads it: radiance scaled by a power of two that keeps the shader's
// floats in range, and the area lights' sampling densities computed in double.
#include <cfloat>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "load/scene_loader.h"
#include "packing/scene_packing.h"
#include "scene/emitters.h"

namespace vkray::gpu {
namespace {

Scene lit_by(const std::string& rest) {
  return parse_scene(R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1},
                         "integrator": {"type": "path"}, )" + rest + "}", "test.json");
}

TEST(ScenePackingTest, TheBrightestRadianceIsBroughtToTwoToTheTwenty) {
  for (const float brightest : {3.4e38f, 3e38f, 18.387f, 1.0f, 1e-25f, 1.17e-38f, 1e-39f, 1.4e-45f}) {
    Scene scene = lit_by(R"("background": [0, 0, 0])");
    scene.background = glm::vec3(brightest * 0.5f, brightest, 0.0f);
    const int k = radiance_exponent(scene);
    const float scaled = std::ldexp(brightest, k);
    EXPECT_GE(scaled, std::ldexp(1.0f, 19)) << brightest;
    EXPECT_LT(scaled, std::ldexp(1.0f, 20)) << brightest;
  }
  EXPECT_EQ(radiance_exponent(lit_by(R"("background": [0, 0, 0])")), 0);  // nothing shines
}

TEST(ScenePackingTest, ScaledRadianceComesBackBitForBit) {
  // Any float the shader computes in range returns exactly; past FLT_MAX it is held at FLT_MAX.
  std::mt19937 random(7);
  std::uniform_real_distribution<float> mantissa(0.5f, 1.0f);
  std::uniform_int_distribution<int> exponent(-125, 128), scale(-200, 200);
  for (int i = 0; i < 100000; ++i) {
    const float v = std::ldexp(mantissa(random), exponent(random));
    const int k = scale(random);
    const float scaled = std::ldexp(v, k);
    if (!(scaled >= FLT_MIN && scaled <= FLT_MAX)) continue;  // the shader never holds such a one
    EXPECT_EQ(unscale_radiance(glm::vec3(scaled), k).x, v) << v << " " << k;
  }
  EXPECT_EQ(unscale_radiance(glm::vec3(1.0f), -200).x, FLT_MAX);
}

TEST(ScenePackingTest, EveryRadianceIsScaledAlike) {
  const Scene scene = lit_by(R"("background": [3e28, 1, 0], "ambient": [0.5, 0, 0],
      "materials": {"e": {"albedo": [0.5, 0.5, 0.5], "emission": [2, 3, 4]}},
      "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [5, 6, 7]}],
      "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1, "material": "e"}])");
  const int k = radiance_exponent(scene);
  const PackedLighting packed = pack_lighting(scene, {0});
  EXPECT_EQ(packed.frame.radiance_exponent, k);
  EXPECT_EQ(packed.materials[VKRAY_MATERIAL_EMISSION].y, std::ldexp(3.0f, k));
  EXPECT_EQ(packed.lights[VKRAY_LIGHT_INTENSITY].z, std::ldexp(7.0f, k));
  const FrameUniforms frame = pack_frame(scene, 1, packed.frame, scene.image);
  EXPECT_EQ(frame.background.x, std::ldexp(3e28f, k));
  EXPECT_EQ(frame.ambient.x, std::ldexp(0.5f, k));
}

TEST(ScenePackingTest, AnAreaLightsDensityIsComputedInDouble) {
  // A sphere of radius 1e-8 emitting 1e-25, the only light: its power, 1.3e-40, is below the
  // smallest normal float, and 1 / power overflows one. Its density per unit area is 1 / area.
  const Scene scene = lit_by(R"("materials": {"e": {"albedo": [0.5, 0.5, 0.5], "emission": [1e-25, 1e-25, 1e-25]}},
      "objects": [{"type": "sphere", "center": [0, 0, 5], "radius": 1e-8, "material": "e"}])");
  const EmitterTable table = build_emitter_table(scene);
  ASSERT_EQ(table.entries.size(), 1u);
  EXPECT_TRUE(std::isinf(float(1.0 / table.total_weight)));
  const PackedLighting packed = pack_lighting(scene, {0});
  const double area = 4.0 * 3.141592653589793 * 1e-8 * 1e-8;
  EXPECT_NEAR(packed.materials[VKRAY_MATERIAL_LIGHT].x, 1.0 / area, 1e-5 / area);
}

}  // namespace
}  // namespace vkray::gpu
