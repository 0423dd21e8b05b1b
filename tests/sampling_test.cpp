// The sample pattern shared by both renderers (shaders/shared/sampling.h compiled as C++).
#include <cmath>
#include <set>
#include <vector>

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
  EXPECT_EQ(gpu::sample_offset(12345, 0, 0, 1, 1, 1.0f, 1.0f), glm::vec2(0.5f, 0.5f));
}

TEST(SamplingTest, EachSampleLiesInItsOwnStratum) {
  for (uint32_t spp : {2u, 4u, 7u, 16u}) {
    const SampleStrata s = sample_strata(spp);
    for (uint32_t pixel : {0u, 1u, 999u, 4000000u}) {
      std::set<std::pair<int, int>> cells;
      for (uint32_t k = 0; k < spp; ++k) {
        const glm::vec2 xi = gpu::sample_offset(pixel, 0, k, spp, s.x, s.inv_x, s.inv_y);
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
  EXPECT_EQ(gpu::sample_offset(77, 0, 5, 16, s.x, s.inv_x, s.inv_y), gpu::sample_offset(77, 0, 5, 16, s.x, s.inv_x, s.inv_y));
  EXPECT_NE(gpu::sample_offset(77, 0, 5, 16, s.x, s.inv_x, s.inv_y), gpu::sample_offset(78, 0, 5, 16, s.x, s.inv_x, s.inv_y));
}

TEST(SamplingTest, SeedZeroKeepsThePatternAndOtherSeedsChangeIt) {
  const SampleStrata s = sample_strata(16);
  EXPECT_EQ(gpu::seed_key(0), 0u);
  EXPECT_NE(gpu::seed_key(1), gpu::seed_key(2));
  // Another seed moves the sample within the same stratum.
  const glm::vec2 a = gpu::sample_offset(77, gpu::seed_key(0), 5, 16, s.x, s.inv_x, s.inv_y);
  const glm::vec2 b = gpu::sample_offset(77, gpu::seed_key(7), 5, 16, s.x, s.inv_x, s.inv_y);
  EXPECT_NE(a, b);
  EXPECT_EQ(uint32_t(a.x * 4), uint32_t(b.x * 4));
  EXPECT_EQ(uint32_t(a.y * 4), uint32_t(b.y * 4));
  EXPECT_NE(gpu::sample_stream(77, gpu::seed_key(0), 5), gpu::sample_stream(77, gpu::seed_key(7), 5));
  EXPECT_NE(gpu::sample_stream(77, 0, 5), gpu::sample_stream(77, 0, 6));
}

TEST(SamplingTest, AJitteredSingleSampleIsNotTheCentre) {
  const glm::vec2 xi = gpu::jittered_offset(12345, 0, 0, 1, 1.0f, 1.0f);
  EXPECT_NE(xi, glm::vec2(0.5f, 0.5f));
  EXPECT_GE(std::min(xi.x, xi.y), 0.0f);
  EXPECT_LT(std::max(xi.x, xi.y), 1.0f);
}

TEST(SamplingTest, StreamsAreUniformAndIndependentOfEachOther) {
  // 64 streams of 4096 numbers: each in [0, 1), means near 1/2, and neighbouring draws uncorrelated.
  double sum = 0, sum_product = 0;
  size_t n = 0;
  std::vector<uint32_t> bins(16, 0);
  for (uint32_t k = 0; k < 64; ++k) {
    uint32_t state = gpu::sample_stream(1000 + k, 0, k);
    float previous = gpu::next_random(state);
    for (int i = 0; i < 4096; ++i, ++n) {
      const float u = gpu::next_random(state);
      ASSERT_GE(u, 0.0f);
      ASSERT_LT(u, 1.0f);
      sum += u;
      sum_product += double(u) * previous;
      ++bins[size_t(u * 16)];
      previous = u;
    }
  }
  // Standard errors: of the mean 0.29 / sqrt(n) = 0.0011; of E[u u'] about 0.0009.
  EXPECT_NEAR(sum / double(n), 0.5, 0.006);
  EXPECT_NEAR(sum_product / double(n), 0.25, 0.005);
  for (const uint32_t b : bins) EXPECT_NEAR(double(b), double(n) / 16, 6 * std::sqrt(double(n) / 16));
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
