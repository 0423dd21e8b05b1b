// GPU vs CPU reference parity: every shipped scene, adversarial cases, and proof that the
// comparison catches a wrong image.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>

#include "support/parity_run.h"

namespace vkray::test {
namespace {

Scene cornell() { return load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"); }

// The same image at another scale: lengths times k, intensities times k^2 (radiance goes as I / r^2).
Scene scaled(Scene s, float k) {
  for (auto& t : s.triangles)
    for (auto& v : t.v) v *= k;
  for (auto& sphere : s.spheres) {
    sphere.center *= k;
    sphere.radius *= k;
  }
  for (auto& l : s.lights) {
    l.position *= k;
    l.intensity *= k * k;
  }
  s.camera.position *= k;
  return s;
}

// ---- Every scene in scenes/, at 1 and 16 samples per pixel ----------------------------------------
struct SceneCase {
  std::string file;
  uint32_t spp;
  bool compiled_in = false;  // InlineScene::always (the scene small enough), else the BVH
};
void PrintTo(const SceneCase& c, std::ostream* os) {
  *os << c.file << " at " << c.spp << " spp" << (c.compiled_in ? ", compiled into the shader" : "");
}

class SceneParityTest : public ParityTest, public ::testing::WithParamInterface<SceneCase> {};

TEST_P(SceneParityTest, WithinTolerance) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / GetParam().file);
  const bool compiled_in = GetParam().compiled_in;
  const ParityResult r =
      run(scene, {256, 256, GetParam().spp}, compiled_in ? InlineScene::always : InlineScene::never);
  EXPECT_EQ(r.gpu.stats.inline_scene, compiled_in);
  expect_parity(r, scene.name + "-" + std::to_string(GetParam().spp) + "spp" + (compiled_in ? "-inline" : ""));
  EXPECT_EQ(r.metrics.interior_over_2, 0u);
}

std::vector<SceneCase> scene_cases() {
  std::vector<SceneCase> cases;
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(VKRAY_SCENE_DIR))
    if (entry.path().extension() == ".json") files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  for (const auto& f : files)
    for (uint32_t spp : {1u, 16u}) cases.push_back({f, spp});
  // The shipped scenes small enough to be compiled into the shader (gpu::kMaxInlinePrimitives).
  for (const char* f : {"cornell.json", "cornell-spheres.json"})
    for (uint32_t spp : {1u, 16u}) cases.push_back({f, spp, true});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Scenes, SceneParityTest, ::testing::ValuesIn(scene_cases()),
                         [](const ::testing::TestParamInfo<SceneCase>& param) {
                           std::string name = param.param.file.substr(0, param.param.file.size() - 5);
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name + "_" + std::to_string(param.param.spp) + "spp" +
                                  (param.param.compiled_in ? "_inline" : "");
                         });

// ---- Adversarial cases, on both GPU paths ------------------------------------------------------------
// Each case runs with the BVH and with the scene compiled into the shader (InlineScene); every
// scene fits in gpu::kMaxInlinePrimitives (the shared-edge case is a smaller grid for it), and each run
// checks that it took the path it asked for.
class AdversarialParityTest : public ParityTest, public ::testing::WithParamInterface<InlineScene> {
 protected:
  ParityResult check(const Scene& scene, const std::string& name, ImageSettings image = {128, 128, 1}) {
    const bool compiled_in = GetParam() == InlineScene::always;
    ParityResult r = run(scene, image, GetParam());
    EXPECT_EQ(r.gpu.stats.inline_scene, compiled_in);
    expect_parity(r, name + (compiled_in ? "-inline" : ""));
    return r;
  }
};

TEST_P(AdversarialParityTest, GrazingRaysAlongAWall) {
  Scene s = cornell();
  s.camera.position = {-0.995f, 0.0f, -0.99f};  // 5 thousandths from the left wall, looking along it
  s.camera.focal_length = 0.6f;
  check(s, "grazing-along-wall");
}

TEST_P(AdversarialParityTest, SharedEdgesHaveNoCracks) {
  // A 40 x 40 grid of quads (3200 triangles sharing edges) filling the view; background magenta.
  // With the scene compiled in: a 4 x 4 grid (32 triangles) instead.
  Scene s = cornell();
  s.triangles.clear();
  s.background = {1, 0, 1};
  const int n = GetParam() == InlineScene::always ? 4 : 40;
  auto p = [&](int i, int j) { return glm::vec3(-3.0f + 6.0f * float(i) / float(n), -3.0f + 6.0f * float(j) / float(n), 0.3f * std::sin(float(i + j))); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      s.triangles.push_back({{p(i, j), p(i + 1, j), p(i + 1, j + 1)}, 6});
      s.triangles.push_back({{p(i, j), p(i + 1, j + 1), p(i, j + 1)}, 6});
    }
  s.camera.position = {0.13f, -0.07f, -3.0f};
  const ParityResult r = check(s, "shared-edges");
  for (const Image* image : {&r.gpu.image, &r.cpu.image}) {
    size_t background = 0;
    for (const auto& px : image->pixels) background += (px == glm::vec3(1, 0, 1));
    EXPECT_EQ(background, 0u) << (image == &r.gpu.image ? "GPU" : "CPU") << " image has cracks";
  }
}

TEST_P(AdversarialParityTest, LightExactlyOnASurface) {
  Scene s = cornell();
  s.lights[0].position = {0.0f, -1.0f, -0.3f};  // on the ceiling plane
  check(s, "light-on-surface");
}

TEST_P(AdversarialParityTest, LightInThePlaneOfATriangle) {
  Scene s = cornell();
  // Level with the short block's top face (triangle 18), beside the block: shadow rays graze the face.
  s.lights[0].position = {0.9f, s.triangles[18].v[0].y, -0.5f};
  check(s, "light-in-triangle-plane");
}

TEST_P(AdversarialParityTest, CameraInThePlaneOfTheFloor) {
  Scene s = cornell();
  s.camera.position = {0.0f, s.triangles[0].v[0].y, -0.9f};
  check(s, "camera-in-floor-plane");
}

TEST_P(AdversarialParityTest, CameraInsideASphere) {
  Scene s = cornell();
  s.triangles.clear();
  s.spheres = {{{0, 0, 0}, 3.0f, 6}, {{0.3f, 0.2f, 1.2f}, 0.5f, 0}};
  s.camera.position = {0, 0, -1};
  s.lights[0].position = {0, -1.5f, 0};
  check(s, "camera-inside-sphere");
}

TEST_P(AdversarialParityTest, SmallSceneScale) { check(scaled(cornell(), 1e-3f), "scale-1e-3"); }

TEST_P(AdversarialParityTest, LargeSceneScale) { check(scaled(cornell(), 1e4f), "scale-1e4"); }

// The largest scenes vkray accepts (scene.h, kMaxCoordinate) render alike: the GPU's float math on
// edge vectors (a normal from a cross product, barycentrics for smooth shading) must not overflow
// where the CPU's double math does not. At 1e12 it did: the GPU lit these surfaces with ambient only.
Scene at_the_coordinate_limit(const std::string& file) {
  const Scene s = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / file);
  return scaled(s, std::nextafter(kMaxCoordinate / s.extent(), 0.0f));
}
TEST_P(AdversarialParityTest, SpheresAndTrianglesAtTheCoordinateLimit) {
  check(at_the_coordinate_limit("cornell-spheres.json"), "cornell-spheres-at-limit");
}
TEST_F(ParityTest, SmoothMeshAtTheCoordinateLimit) {  // too large to compile in: the BVH path only
  expect_parity(run(at_the_coordinate_limit("teapot.json"), {128, 128, 1}, InlineScene::never), "teapot-at-limit");
}

TEST_P(AdversarialParityTest, LightBehindASurface) {
  Scene s = cornell();
  s.lights[0].position = {0.0f, -0.5f, 1.5f};  // behind the back wall: only ambient reaches the room
  const ParityResult r = check(s, "light-behind-surface");
  EXPECT_NEAR(r.cpu.image.at(64, 40).r, 0.75f * 0.1f, 1e-6f);  // the back wall, ambient only
  EXPECT_NEAR(r.gpu.image.at(64, 40).r, 0.75f * 0.1f, 1e-6f);
}

TEST_P(AdversarialParityTest, SixteenLights) {
  Scene s = cornell();
  const PointLight base = s.lights[0];
  s.lights.clear();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      s.lights.push_back({{-0.75f + 0.5f * float(i), -0.9f, -0.75f + 0.5f * float(j)}, base.intensity / 16.0f});
  check(s, "sixteen-lights");
}

INSTANTIATE_TEST_SUITE_P(Paths, AdversarialParityTest, ::testing::Values(InlineScene::never, InlineScene::always),
                         [](const ::testing::TestParamInfo<InlineScene>& param) {
                           return param.param == InlineScene::always ? "inline" : "bvh";
                         });

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
