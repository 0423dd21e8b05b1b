// The first-hit passes on both renderers, against geometry whose answers are known: a sphere in
// front of a wall, seen head on; and proof that parity notices a pass the shader gets wrong.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "image/aovs.h"
#include "session/cpu_render.h"
#include "shared/first_hit_layout.h"
#include "support/parity_run.h"
#include "support/temp_dir.h"
#include "load/scene_loader.h"

namespace vkray::test {
namespace {

// A camera at the origin looking down -z; a wall (object 0, grey) at z = -10 covering the image's
// middle band, and a sphere (object 1, red, radius 1) at z = -5 in the middle; the rest is sky.
// A direct-model scene, or a path-traced one.
std::string scene_json(bool path) {
  return std::string(R"({
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "vertical_fov": 40},)") +
         (path ? R"("integrator": {"type": "path"}, "background": [0.2, 0.2, 0.2],)" : "") + R"(
    "lights": [{"type": "point", "position": [0, 5, 0], "intensity": [50, 50, 50]}],
    "materials": {"grey": {"albedo": [0.5, 0.5, 0.5]}, "red": {"albedo": [0.9, 0.1, 0.1]}},
    "objects": [
      {"type": "triangles", "material": "grey", "positions": [[-20, -1.5, -10], [20, -1.5, -10], [20, 1.5, -10], [-20, 1.5, -10]],
       "indices": [[0, 1, 2], [0, 2, 3]]},
      {"type": "sphere", "center": [0, 0, -5], "radius": 1, "material": "red"}]})";
}

// Checks the passes a renderer returned at three pixels whose answers are known.
void expect_known_passes(const Aovs& aovs, const char* renderer) {
  SCOPED_TRACE(renderer);
  const uint32_t w = aovs.width, h = aovs.height;
  // The centre: near the sphere's nearest point (0, 0, -4), facing the camera, 4 away (the pixel's
  // samples spread over a degree of the sphere).
  const size_t centre = size_t(h / 2) * w + w / 2;
  EXPECT_EQ(aovs.object[centre], 1);
  EXPECT_NEAR(aovs.depth[centre], 4.0, 1e-2);
  EXPECT_NEAR(aovs.normal[centre].z, 1.0, 1e-2);
  EXPECT_NEAR(aovs.position[centre].z, -4.0, 1e-2);
  // On the sphere (a mean of points on it lies a little inside).
  EXPECT_NEAR(glm::length(aovs.position[centre] - glm::vec3(0, 0, -5)), 1.0, 5e-3);
  EXPECT_NEAR(aovs.albedo[centre].r, 0.9, 1e-6);
  EXPECT_NEAR(aovs.albedo[centre].g, 0.1, 1e-6);
  // Left of the sphere, on the wall's centre line: the wall at z = -10, facing the camera.
  const size_t wall = size_t(h / 2) * w + w / 8;
  EXPECT_EQ(aovs.object[wall], 0);
  EXPECT_NEAR(aovs.position[wall].z, -10.0, 1e-3);
  EXPECT_NEAR(aovs.normal[wall].z, 1.0, 1e-6);
  EXPECT_GT(aovs.depth[wall], 10.0);
  EXPECT_NEAR(aovs.albedo[wall].g, 0.5, 1e-6);
  // The top row: sky. Nothing hit: no object, infinite depth, zero passes.
  const size_t sky = w / 2;
  EXPECT_EQ(aovs.object[sky], -1);
  EXPECT_TRUE(std::isinf(aovs.depth[sky]) && aovs.depth[sky] > 0);
  EXPECT_EQ(aovs.albedo[sky], glm::vec3(0.0f));
  EXPECT_EQ(aovs.normal[sky], glm::vec3(0.0f));
}

class AovTest : public ParityTest, public ::testing::WithParamInterface<bool> {};

TEST_P(AovTest, BothRenderersReturnTheKnownFirstHits) {
  const Scene scene = parse_scene(scene_json(GetParam()), "aovs.json");
  RenderOptions options = with_image({}, {64, 48, 4});
  options.aovs = true;
  const RenderResult gpu = session().render(session().upload(std::make_shared<const Scene>(scene)), options);
  const RenderResult cpu = render_on_cpu(scene, options);
  ASSERT_TRUE(gpu.aovs && cpu.aovs);
  expect_known_passes(*gpu.aovs, "GPU");
  expect_known_passes(*cpu.aovs, "CPU");
}

TEST_P(AovTest, ParityCoversThePasses) {
  const Scene scene = parse_scene(scene_json(GetParam()), "aovs.json");
  const ParityResult result = run(scene, {96, 64, 9});
  EXPECT_TRUE(result.metrics.aovs_compared);
  expect_parity(result, GetParam() ? "aovs-path" : "aovs-direct");
}

TEST_P(AovTest, PassesContinueAcrossTheDispatchesOfATile) {
  // More samples than one dispatch traces (at most 64): later dispatches continue the sums.
  const Scene scene = parse_scene(scene_json(GetParam()), "aovs.json");
  const ParityResult result = run(scene, {32, 24, 150});
  expect_known_passes(*result.gpu.aovs, "GPU");
  expect_parity(result, GetParam() ? "aovs-path-150spp" : "aovs-direct-150spp");
}

TEST_P(AovTest, ARenderWithoutPassesReturnsNone) {
  const Scene scene = parse_scene(scene_json(GetParam()), "aovs.json");
  const RenderOptions options = with_image({}, {16, 16, 1});
  EXPECT_FALSE(session().render(session().upload(std::make_shared<const Scene>(scene)), options).aovs);
  EXPECT_FALSE(render_on_cpu(scene, options).aovs);
}

INSTANTIATE_TEST_SUITE_P(Integrators, AovTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& p) { return p.param ? "Path" : "Direct"; });

// A shader whose normal pass is turned to face the ray (a plausible slip: the shading code does
// that) must fail parity on the passes alone: the image is unchanged.
class BrokenNormalPassTest : public BrokenShaderParityTest {
 protected:
  BrokenNormalPassTest()
      : BrokenShaderParityTest("aovs.glsl", "first_hits.normal += s.shading_normal;", "first_hits.normal += abs(s.shading_normal);") {}
};

TEST_F(BrokenNormalPassTest, FailsParity) {
  const Scene scene = parse_scene(scene_json(false), "aovs.json");
  const ParityResult result = run(scene, {96, 64, 1});
  EXPECT_FALSE(result.metrics.pass);
  EXPECT_GT(result.metrics.aov_differing_by_pass[size_t(Aov::normal)], 0u);
  EXPECT_EQ(result.metrics.interior_over_1, 0u);  // the image itself is right
}

TEST(AovListTest, ParsesNamesAndRefusesUnknownOrRepeatedOnes) {
  EXPECT_EQ(parse_aov_list("depth,albedo"), (std::vector<Aov>{Aov::depth, Aov::albedo}));
  EXPECT_EQ(parse_aov_list("albedo,normal,position,depth,object").size(), 5u);
  EXPECT_THROW(parse_aov_list("albedo,colour"), UsageError);
  EXPECT_THROW(parse_aov_list("depth,depth"), UsageError);
  EXPECT_THROW(parse_aov_list(""), UsageError);
  EXPECT_THROW(parse_aov_list("albedo,"), UsageError);
  try {
    parse_aov_list("normals");
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("\"normals\""), std::string::npos) << e.what();
  }
}

TEST(FirstHitLayoutTest, EverySumComesBackAsItWasPacked) {
  // The shader packs with these functions and the host unpacks with them: each sum in its own
  // place, the count and the object as exact bits (the object may be -1, a NaN's bits as a float).
  using namespace gpu;
  const FirstHitTexels t = first_hit_texels(vec3(0.25f, 0.5f, 1.0f), 0xfffffffeu, vec3(-1.0f, 0.0f, 2.0f), -1,
                                            vec3(3.0f, -4.0f, 5.0f), 6.5f);
  EXPECT_EQ(first_hit_albedo(t), vec3(0.25f, 0.5f, 1.0f));
  EXPECT_EQ(first_hit_count(t), 0xfffffffeu);
  EXPECT_EQ(first_hit_normal(t), vec3(-1.0f, 0.0f, 2.0f));
  EXPECT_EQ(first_hit_object(t), -1);
  EXPECT_EQ(first_hit_position(t), vec3(3.0f, -4.0f, 5.0f));
  EXPECT_EQ(first_hit_depth(t), 6.5f);
  EXPECT_EQ(first_hit_object(first_hit_texels(vec3(0.0f), 1u, vec3(0.0f), 123456, vec3(0.0f), 0.0f)), 123456);
}

}  // namespace
}  // namespace vkray::test
