// The sample pattern shared by both renderers (shaders/shared/sampling.h compiled as C++).
#include <set>

#include <gtest/gtest.h>

#include "scene/camera.h"
#include "shared/sampling.h"

namespace vkray {
namespace {

TEST(SamplingTest, StrataCoverTheSampleCount) {
  struct Expect { uint32_t spp, x, y; };
  for (const auto& e : {Expect{1, 1, 1}, {2, 2, 1}, {4, 2, 2}, {5, 3, 2}, {9, 3, 3}, {16, 4, 4}, {17, 5, 4}, {65536, 256, 256}}) {
    const SampleStrata s = sample_strata(e.spp);
    EXPECT_EQ(s.x, e.x) << e.spp;
    EXPECT_EQ(s.y, e.y) << e.spp;
    EXPECT_GE(s.x * s.y, e.spp);
  }
}

TEST(SamplingTest, OneSampleIsThePixelCentre) {
  EXPECT_EQ(gpu::sample_offset(12345, 0, 1, 1, 1.0f, 1.0f), glm::vec2(0.5f, 0.5f));
}

TEST(SamplingTest, EachSampleLiesInItsOwnStratum) {
  for (uint32_t spp : {2u, 4u, 7u, 16u}) {
    const SampleStrata s = sample_strata(spp);
    for (uint32_t pixel : {0u, 1u, 999u, 4000000u}) {
      std::set<std::pair<int, int>> cells;
      for (uint32_t k = 0; k < spp; ++k) {
        const glm::vec2 xi = gpu::sample_offset(pixel, k, spp, s.x, s.inv_x, s.inv_y);
        ASSERT_GE(xi.x, 0.0f);
        ASSERT_LT(xi.x, 1.0f);
        ASSERT_GE(xi.y, 0.0f);
        ASSERT_LT(xi.y, 1.0f);
        EXPECT_EQ(uint32_t(xi.x * float(s.x)), k % s.x);
        EXPECT_EQ(uint32_t(xi.y * float(s.y)), k / s.x);
        cells.insert({int(xi.x * float(s.x)), int(xi.y * float(s.y))});
      }
      EXPECT_EQ(cells.size(), spp);
    }
  }
}

TEST(SamplingTest, PatternDependsOnlyOnPixelAndSample) {
  const SampleStrata s = sample_strata(16);
  EXPECT_EQ(gpu::sample_offset(77, 5, 16, s.x, s.inv_x, s.inv_y), gpu::sample_offset(77, 5, 16, s.x, s.inv_x, s.inv_y));
  EXPECT_NE(gpu::sample_offset(77, 5, 16, s.x, s.inv_x, s.inv_y), gpu::sample_offset(78, 5, 16, s.x, s.inv_x, s.inv_y));
}

TEST(SamplingTest, PcgHashKnownValues) {
  // Pinned so that a change to the shared pattern (which would change every multi-sample image) is seen.
  EXPECT_EQ(gpu::pcg_hash(0u), 129708002u);
  EXPECT_EQ(gpu::pcg_hash(1u), 2831084092u);  // both computed independently in Python
}

TEST(CameraTest, BasisFollowsTheContract) {
  Camera cam;
  cam.position = {0, 0, -3};
  cam.forward = {0, 0, 1};
  cam.up = {0, -1, 0};
  cam.focal_length = 1.0f;
  const CameraBasis b = camera_basis(cam, 256);
  EXPECT_EQ(b.right, glm::vec3(1, 0, 0));  // f x up = (0,0,1) x (0,-1,0)
  EXPECT_EQ(b.up, glm::vec3(0, -1, 0));    // r x f
  EXPECT_EQ(b.focal_px, 256.0f);
}

}  // namespace
}  // namespace vkray
