// Properties of the CPU reference that need no device.
#include <filesystem>

#include <gtest/gtest.h>

#include "cpu/reference.h"

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
