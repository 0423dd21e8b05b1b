// GPU vs CPU reference parity: what the check cases must show beyond the tolerance, and proof that
// the comparison catches a wrong image.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>

#include "compare/check.h"
#include "support/parity_run.h"
#include "load/scene_loader.h"

namespace vkray::test {
namespace {

Scene cornell() { return load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"); }

// ---- The check cases (`vkray check`), with what parity alone cannot see ----------------------------
// The whole suite runs as `vkray check` installed (installed_check.sh, a CTest test): every shipped
// scene and every adversarial case in checks/, on both GPU paths, at 1 and 16 spp. These tests hold
// some of its cases to more than the tolerance, on both paths.
Scene check_case(const char* name) { return load_scene(std::filesystem::path(VKRAY_CHECK_DIR) / (std::string(name) + ".json")); }

class CheckCaseTest : public ParityTest, public ::testing::WithParamInterface<InlineScene> {
 protected:
  ParityResult check(const Scene& scene, const std::string& name, ImageSettings image = {128, 128, 1}) {
    const bool compiled_in = GetParam() == InlineScene::always;
    ParityResult r = run(scene, image, GetParam());
    EXPECT_EQ(r.gpu.stats.inline_scene, compiled_in);
    expect_parity(r, name + (compiled_in ? "-inline" : ""));
    return r;
  }
};

TEST_P(CheckCaseTest, SharedEdgesHaveNoCracks) {
  // Triangles sharing edges fill the view over a magenta background: no ray may pass between them.
  // Compiled in: the 4 x 4 grid (32 triangles) instead of the 40 x 40.
  const bool compiled_in = GetParam() == InlineScene::always;
  const ParityResult r = check(check_case(compiled_in ? "shared-edges-small" : "shared-edges"), "shared-edges");
  for (const Image* image : {&r.gpu.image, &r.cpu.image}) {
    size_t background = 0;
    for (const auto& px : image->pixels) background += (px == glm::vec3(1, 0, 1));
    EXPECT_EQ(background, 0u) << (image == &r.gpu.image ? "GPU" : "CPU") << " image has cracks";
  }
}

TEST_P(CheckCaseTest, LightBehindASurfaceLeavesAmbientOnly) {
  const ParityResult r = check(check_case("light-behind-surface"), "light-behind-surface");
  EXPECT_NEAR(r.cpu.image.at(64, 40).r, 0.75f * 0.1f, 1e-6f);  // the back wall, ambient only
  EXPECT_NEAR(r.gpu.image.at(64, 40).r, 0.75f * 0.1f, 1e-6f);
}

TEST_P(CheckCaseTest, ALightOnASurfaceLightsNothingThere) {
  // The ceiling holds the light: ambient only on it, on both renderers (the contract's height rule).
  const ParityResult r = check(check_case("light-on-surface"), "light-on-surface");
  for (const Image* image : {&r.gpu.image, &r.cpu.image})
    for (const uint32_t x : {60u, 63u, 64u, 67u})  // the ceiling beside the light (at 128 x 128)
      EXPECT_NEAR(image->at(x, 16).g, 0.75f * 0.1f, 1e-6f) << (image == &r.gpu.image ? "GPU" : "CPU") << " x " << x;
}

TEST_P(CheckCaseTest, ScaledScenesGiveTheSameImage) {
  // Lengths times k and intensities times k^2: the same radiance, to float precision away from edges
  // (where the crease between two walls falls on one side or the other, by rounding).
  const ParityResult unscaled = check(load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"), "cornell");
  for (const char* name : {"scale-1e-3", "scale-1e4", "scale-1e-9"}) {
    const ParityResult r = check(check_case(name), name);
    const ParityMetrics m = compare_images(r.gpu.image, unscaled.gpu.image, unscaled.signatures);
    EXPECT_EQ(m.interior_over_1, 0u) << name << ": " << describe_metrics(m);
  }
}

TEST_P(CheckCaseTest, ThousandsOfSamplesPerPixelMatchTheReference) {
  // A dispatch traces at most 64 samples of a pixel, 256 with the scene compiled in (gpu/renderer.cpp,
  // samples_in_one_dispatch): in one dispatch llvmpipe's loop limiter silently ended the samples of
  // 2048 spp early, an image 29% too dark.
  const ParityResult r = check(cornell(), "cornell-4096spp", {16, 16, 4096});
  EXPECT_EQ(r.metrics.interior_over_1, 0u);
  EXPECT_EQ(r.gpu.stats.rays, r.cpu.stats.rays);  // every sample traced, and each of its shadow rays
}

INSTANTIATE_TEST_SUITE_P(Paths, CheckCaseTest, ::testing::Values(InlineScene::never, InlineScene::always),
                         [](const ::testing::TestParamInfo<InlineScene>& param) {
                           return param.param == InlineScene::always ? "inline" : "bvh";
                         });

// ---- The ends of the float range ----------------------------------------------------------------------
// Radiance near the largest and below the smallest normal 32-bit float, an area light whose power
// is below what a float holds, a lens as wide as a scene allows: the GPU's image is finite and agrees
// with the double-precision reference, whose image is finite too.
class FloatRangeTest : public ParityTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(FloatRangeTest, TheGpuStaysFiniteAndAgreesWithTheReference) {
  const ParityResult r = run(check_case(GetParam()), {96, 96, 16});
  for (const RenderResult* result : {&r.gpu, &r.cpu})
    for (const glm::vec3& p : result->image.pixels)
      ASSERT_TRUE(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b))
          << (result == &r.gpu ? "GPU" : "CPU") << " pixel (" << p.r << ", " << p.g << ", " << p.b << ")";
  expect_parity(r, GetParam());
}

INSTANTIATE_TEST_SUITE_P(Checks, FloatRangeTest,
                         ::testing::Values("sky-at-float-max", "lights-at-float-limits", "dim-small-light", "aperture-at-limit"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           std::string name = param.param;
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name;
                         });

// The suite finds its cases: every shipped scene and every file in checks/, in a fixed order.
TEST(CheckSuiteTest, ListsTheShippedScenesThenTheAdversarialCases) {
  const auto scenes = check_scenes({VKRAY_SCENE_DIR, VKRAY_CHECK_DIR});
  std::vector<std::string> names;
  for (const auto& s : scenes) names.push_back(s.stem().string());
  for (const char* name : {"cornell", "bunny", "dragon-field", "light-on-surface", "shared-edges", "teapot-at-limit"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  EXPECT_EQ(scenes.front().parent_path(), std::filesystem::path(VKRAY_SCENE_DIR));
  EXPECT_EQ(scenes.back().parent_path(), std::filesystem::path(VKRAY_CHECK_DIR));
}

// ---- The comparison itself can fail -------------------------------------------------------------------
class ComparisonTest : public ParityTest {
 protected:
  void SetUp() override {
    ParityTest::SetUp();
    run_ = run(cornell(), {128, 128, 1});
    ASSERT_TRUE(run_.metrics.pass);
  }
  ParityMetrics compare(const Image& gpu) { return compare_images(gpu, run_.cpu.image, run_.signatures); }
  ParityResult run_;
};

TEST_F(ComparisonTest, CatchesImageTwoPercentTooBright) {
  Image brighter = run_.gpu.image;
  for (auto& p : brighter.pixels) p *= 1.02f;
  const ParityMetrics m = compare(brighter);
  EXPECT_FALSE(m.pass);
  EXPECT_GT(m.interior_over_1, 100u);
}

TEST_F(ComparisonTest, CatchesOneWrongPixelAwayFromEdges) {
  Image one = run_.gpu.image;
  one.at(64, 40) += glm::vec3(0.5f);  // the back wall, far from any edge
  const ParityMetrics m = compare(one);
  EXPECT_FALSE(m.pass);
  EXPECT_EQ(m.interior_over_1, 1u);
  EXPECT_EQ(m.worst_x, 64u);
  EXPECT_EQ(m.worst_y, 40u);
}

TEST_F(ComparisonTest, AcceptsNoiseBelowOneStep) {
  Image noisy = run_.gpu.image;
  for (auto& p : noisy.pixels) p += glm::vec3(1e-6f);
  EXPECT_TRUE(compare(noisy).pass);
}

}  // namespace
}  // namespace vkray::test
