// The parity metrics and tolerance on hand-made images.
#include <cmath>

#include <gtest/gtest.h>

#include "compare/parity_metrics.h"

namespace vkray {
namespace {

// 8 x 4 image, left half signature 1, right half signature 2: columns 3 and 4 are the edge.
struct Pair {
  Image gpu{8, 4}, cpu{8, 4};
  std::vector<uint64_t> signatures = std::vector<uint64_t>(32, 1);
  Pair() {
    for (uint32_t y = 0; y < 4; ++y)
      for (uint32_t x = 0; x < 8; ++x) {
        cpu.at(x, y) = gpu.at(x, y) = glm::vec3(0.5f);
        if (x >= 4) signatures[y * 8 + x] = 2;
      }
  }
};

TEST(ParityMetricsTest, IdenticalImagesPass) {
  const Pair p;
  const ParityMetrics m = compare_images(p.gpu, p.cpu, p.signatures);
  EXPECT_TRUE(m.pass);
  EXPECT_EQ(m.max_abs, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr));
  EXPECT_EQ(m.edge_pixels, 8u);  // columns 3 and 4
}

TEST(ParityMetricsTest, MetricsOfOneKnownDifference) {
  Pair p;
  p.gpu.at(1, 2).g = 0.6f;  // 0.5 -> 0.6: sRGB 188 -> 203, 15 steps
  const ParityMetrics m = compare_images(p.gpu, p.cpu, p.signatures);
  EXPECT_NEAR(m.max_abs, 0.1, 1e-6);
  EXPECT_NEAR(m.mean_abs, 0.1 / 96.0, 1e-8);
  EXPECT_NEAR(m.psnr, 10 * std::log10(96.0 / 0.01), 1e-3);  // MSE = 0.01 / 96
  EXPECT_EQ(m.over_1, 1u);
  EXPECT_EQ(m.over_2, 1u);
  EXPECT_EQ(m.interior_over_1, 1u);
  EXPECT_EQ(m.worst_x, 1u);
  EXPECT_EQ(m.worst_y, 2u);
  EXPECT_FALSE(m.pass);  // one pixel away from an edge
}

TEST(ParityMetricsTest, EdgePixelsMayDifferUpToTheShare) {
  Pair p;
  p.gpu.at(3, 0) = glm::vec3(0.0f);  // on the edge
  const ParityMetrics m = compare_images(p.gpu, p.cpu, p.signatures);
  EXPECT_EQ(m.interior_over_1, 0u);
  EXPECT_EQ(m.over_1, 1u);
  EXPECT_EQ(m.edge_over_1, 1u);
  // 1 of the 8 edge pixels (12.5%) is over the default 2% share; with a share of 1/8 it passes.
  EXPECT_FALSE(m.pass);
  ParityTolerance loose;
  loose.max_edge_share_over_1 = 0.125;
  EXPECT_TRUE(compare_images(p.gpu, p.cpu, p.signatures, loose).pass);
}

TEST(ParityMetricsTest, OneStepDifferencesAreAllowedAnywhere) {
  Pair p;
  for (auto& px : p.gpu.pixels) px = glm::vec3(0.503f);  // 188 -> 189: one step
  const ParityMetrics m = compare_images(p.gpu, p.cpu, p.signatures);
  EXPECT_EQ(m.over_1, 0u);
  EXPECT_TRUE(m.pass);
}

TEST(ParityMetricsTest, NanIsTheWorstDifference) {
  Pair p;
  p.gpu.at(6, 1).r = std::nanf("");
  const ParityMetrics m = compare_images(p.gpu, p.cpu, p.signatures);
  EXPECT_TRUE(std::isinf(m.max_abs));
  EXPECT_EQ(m.worst_x, 6u);
  EXPECT_FALSE(m.pass);
}

TEST(ParityMetricsTest, HeatmapMarksOnlyVisibleDifferences) {
  Pair p;
  p.gpu.at(1, 1) = glm::vec3(0.5f + 1e-6f);  // invisible
  p.gpu.at(2, 2) = glm::vec3(0.9f);          // visible
  int max_steps = 0;
  const Image heat = difference_heatmap(p.gpu, p.cpu, max_steps);
  EXPECT_GT(max_steps, 2);
  EXPECT_EQ(heat.at(1, 1), heat.at(0, 0));  // same grey as an identical pixel
  EXPECT_NE(heat.at(2, 2), heat.at(0, 0));
}

}  // namespace
}  // namespace vkray
