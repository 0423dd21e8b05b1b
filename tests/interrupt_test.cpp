// The interrupt request (base/interrupt.h) is polled by every long loop of the library: with a
// request standing, each stage throws Cancelled at once instead of running on. signal_test.cpp
// checks the same end to end, by the clock; these check each stage on its own.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/errors.h"
#include "base/interrupt.h"
#include "bvh/bvh.h"
#include "cpu/reference.h"
#include "image/image.h"
#include "image/image_file.h"
#include "load/mesh_file.h"
#include "packing/scene_packing.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "support/temp_dir.h"

namespace vkray {
namespace {

class InterruptTest : public ::testing::Test {
 protected:
  void SetUp() override { cornell_ = load_scene(std::filesystem::path(VKRAY_SCENE_DIR) / "cornell.json"); }
  // Each test asks for the stop right before the stage, as the signal thread would.
  void TearDown() override { clear_interrupt(); }
  Scene cornell_;
};

TEST_F(InterruptTest, SceneParsingStops) {
  std::string big = R"({"camera": {"position": [0, 0, 0], "direction": [0, 0, 1], "focal_length": 1}, "x": [0)";
  for (int i = 0; i < 100000; ++i) big += ", 0";
  big += "]}";
  request_interrupt();
  EXPECT_THROW(parse_scene(big, "big.json"), Cancelled);
}

TEST_F(InterruptTest, MeshReadingStops) {
  std::string obj;
  for (int i = 0; i < 10000; ++i) obj += "v 0 0 0\n";
  obj += "f 1 2 3\n";
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  request_interrupt();
  EXPECT_THROW(parse_mesh(obj, "m.obj"), Cancelled);
  EXPECT_THROW(parse_mesh(ply, "m.ply"), Cancelled);
}

TEST_F(InterruptTest, BvhBuildAndPackingStop) {
  const Bvh bvh = build_bvh(primitive_boxes(cornell_));
  request_interrupt();
  EXPECT_THROW(build_bvh(primitive_boxes(cornell_)), Cancelled);
  EXPECT_THROW(gpu::pack_scene(cornell_, bvh), Cancelled);
}

TEST_F(InterruptTest, TheCpuReferenceStops) {
  request_interrupt();
  EXPECT_THROW(cpu::render_reference(cornell_, {64, 64, 1}), Cancelled);
}

TEST_F(InterruptTest, ImageWritingStopsAndLeavesNothing) {
  const test::TempDir dir;
  const Image image(64, 64);
  request_interrupt();
  EXPECT_THROW(write_image(image, dir / "out.png"), Cancelled);
  EXPECT_THROW(write_image(image, dir / "out.pfm"), Cancelled);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST_F(InterruptTest, ClearingTheRequestLetsWorkGoOn) {
  request_interrupt();
  clear_interrupt();
  EXPECT_NO_THROW(cpu::render_reference(cornell_, {16, 16, 1}));
}

}  // namespace
}  // namespace vkray
