// Properties of the CPU reference that need no device.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "cpu/reference.h"
#include "load/scene_loader.h"

namespace vkray {
namespace {

TEST(ReferenceTest, ImageDoesNotDependOnThreadCount) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "transforms.json");
  cpu::ReferenceOptions one, three;
  one.threads = 1;
  three.threads = 3;
  const auto a = cpu::render_reference(scene, {97, 61, 4}, one);
  const auto b = cpu::render_reference(scene, {97, 61, 4}, three);
  EXPECT_EQ(a.image.pixels, b.image.pixels);
  EXPECT_EQ(a.signatures, b.signatures);
  EXPECT_EQ(a.rays, b.rays);
}

TEST(ReferenceTest, BvhTraversalFindsWhatBruteForceFinds) {
  for (const char* file : {"transforms.json", "teapot.json", "cornell-spheres.json"}) {
    SCOPED_TRACE(file);
    const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / file);
    cpu::ReferenceOptions brute;
    brute.use_bvh = false;
    const auto a = cpu::render_reference(scene, {48, 36, 1});
    const auto b = cpu::render_reference(scene, {48, 36, 1}, brute);
    EXPECT_EQ(a.signatures, b.signatures);  // same primitive and lights for every sample
    EXPECT_EQ(a.image.pixels, b.image.pixels);
  }
}

TEST(ReferenceTest, ALightOnASurfaceGivesTheSameImageWhateverTheRounding) {
  // The light on the Cornell box's ceiling (as in the parity case light-on-surface). Every renderer
  // rounds the hit point x its own way (a GPU's float by about an ulp of the coordinates), and the
  // cosine term amplifies that near the light: moved by 2 ulps into the room, the light added 0.039
  // to the two ceiling pixels beside it (about 20 8-bit steps), which is how the NVIDIA H100 failed
  // this parity case away from any edge. The contract's height rule (a light at most epsilon above
  // the plane of n lights nothing there) makes the image the same for any such rounding.
  Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
  scene.lights[0].position = {0.0f, -1.0f, -0.3f};
  const auto on_the_ceiling = cpu::render_reference(scene, {128, 128, 1});
  for (const float rounding : {2.4e-7f, -2.4e-7f}) {
    Scene moved = scene;
    moved.lights[0].position.y += rounding;
    const Image image = cpu::render_reference(moved, {128, 128, 1}).image;
    float largest = 0;  // moving the light changes every lit pixel a little; none by a visible step
    for (size_t i = 0; i < image.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) largest = std::max(largest, std::abs(image.pixels[i][c] - on_the_ceiling.image.pixels[i][c]));
    EXPECT_LT(largest, 1e-5f) << "light moved by " << rounding;
  }
}

TEST(ReferenceTest, CountsCameraAndShadowRays) {
  // One sphere filling the view, one light in front of it: every camera ray hits and casts one shadow ray.
  const Scene scene = parse_scene(R"({
    "camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 4},
    "materials": {"m": {"albedo": [1, 1, 1]}},
    "lights": [{"type": "point", "position": [0, 0, 1], "intensity": [1, 1, 1]}],
    "objects": [{"type": "sphere", "center": [0, 0, 10], "radius": 5, "material": "m"}]})", "t.json");
  const auto r = cpu::render_reference(scene, {16, 16, 2});
  EXPECT_EQ(r.rays, 16u * 16u * 2u * 2u);
}

TEST(ReferenceTest, ReportsProgressForEveryRow) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json");
  uint32_t calls = 0, last = 0;
  cpu::ReferenceOptions options;
  options.progress = [&](uint32_t done, uint32_t total) {
    ++calls;
    last = done;
    EXPECT_EQ(total, 24u);
  };
  cpu::render_reference(scene, {16, 24, 1}, options);
  EXPECT_EQ(calls, 24u);
  EXPECT_EQ(last, 24u);
}

}  // namespace
}  // namespace vkray
