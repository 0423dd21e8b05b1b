// How an image is cut into submissions (gpu/tiling.h): every pixel exactly once, in rectangles no
// larger than asked for, and submission sizes that follow the measured time within their bounds.
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/tiling.h"

namespace vkray::gpu {
namespace {

// Takes rectangles until the image is covered, asking for `pixels(i)` for the i-th; checks that no
// pixel is covered twice or left out, and that each rectangle holds at most what was asked for
// (or the smallest piece, granule x granule).
template <typename Ask>
void expect_exact_cover(uint32_t width, uint32_t height, uint32_t granule, Ask pixels) {
  SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height));
  std::vector<uint8_t> covered(size_t(width) * height, 0);
  TileCursor cursor(width, height, granule);
  uint64_t total = 0;
  for (uint32_t i = 0; !cursor.done(); ++i) {
    ASSERT_LT(i, width * height) << "the cursor does not advance";
    const uint64_t asked = pixels(i);
    const TileRect rect = cursor.next(asked);
    ASSERT_GE(rect.width, 1u);
    ASSERT_GE(rect.height, 1u);
    ASSERT_LE(rect.x0 + rect.width, width);
    ASSERT_LE(rect.y0 + rect.height, height);
    EXPECT_LE(rect.pixels(), std::max<uint64_t>(asked, uint64_t(granule) * granule)) << "submission " << i;
    for (uint32_t y = rect.y0; y < rect.y0 + rect.height; ++y)
      for (uint32_t x = rect.x0; x < rect.x0 + rect.width; ++x) ASSERT_EQ(covered[size_t(y) * width + x]++, 0) << x << "," << y;
    total += rect.pixels();
  }
  EXPECT_EQ(total, uint64_t(width) * height);
  for (size_t i = 0; i < covered.size(); ++i) ASSERT_EQ(covered[i], 1) << "pixel " << i;
}

TEST(TilingTest, BandsAndPiecesCoverTheImageExactlyOnce) {
  std::mt19937 rng(3);
  for (const auto& [w, h] : std::vector<std::pair<uint32_t, uint32_t>>{{1, 1}, {7, 5}, {8, 8}, {100, 76}, {512, 512}, {1000, 3}, {3, 1000}}) {
    for (const uint64_t fixed : {1ull, 64ull, 100ull, 4096ull, 20000ull, 1ull << 30})
      expect_exact_cover(w, h, 8, [&](uint32_t) { return fixed; });
    std::uniform_int_distribution<uint64_t> any(1, uint64_t(w) * h * 2);
    expect_exact_cover(w, h, 8, [&](uint32_t) { return any(rng); });  // sizes changing mid-band
  }
}

TEST(TilingTest, ARequestForAGranulesRowsOrMoreGivesWholeRows) {
  TileCursor cursor(1000, 600, 8);
  const TileRect band = cursor.next(1000 * 20);  // 20 rows: the band takes 16, a multiple of 8
  EXPECT_EQ(band.x0, 0u);
  EXPECT_EQ(band.width, 1000u);
  EXPECT_EQ(band.height, 16u);
  const TileRect piece = cursor.next(8 * 100);  // less than one band of 8 rows: a piece of one
  EXPECT_EQ(piece.y0, 16u);
  EXPECT_EQ(piece.height, 8u);
  EXPECT_EQ(piece.width, 96u);
  const TileRect rest = cursor.next(1000 * 600);  // the rest of the band in progress, not more
  EXPECT_EQ(rest.x0, 96u);
  EXPECT_EQ(rest.height, 8u);
  EXPECT_EQ(rest.width, 904u);
  const TileRect last = cursor.next(1000 * 600);
  EXPECT_EQ(last.y0, 24u);
  EXPECT_EQ(last.height, 576u);
  EXPECT_TRUE(cursor.done());
}

TEST(TilingTest, SquaresGoInRowsOfSquares) {
  TileCursor cursor(100, 76, 8);
  std::vector<TileRect> tiles;
  while (!cursor.done()) tiles.push_back(cursor.next_square(16));
  ASSERT_EQ(tiles.size(), 7u * 5u);  // the last row and column partial
  EXPECT_EQ(tiles[6].x0, 96u);
  EXPECT_EQ(tiles[6].width, 4u);
  EXPECT_EQ(tiles[7].y0, 16u);
  EXPECT_EQ(tiles.back().height, 12u);
}

TEST(TilingTest, TheSizerAimsAtTheTargetTimeAndChangesBoundedly) {
  SubmissionSizer sizer(1000, 100, 1'000'000, 0.1);
  EXPECT_EQ(sizer.next(), 1000u);
  sizer.finished(1000, 0.001);  // 1e6 pixels/s: 1e5 wanted, 8x at most
  EXPECT_EQ(sizer.next(), 8000u);
  sizer.finished(8000, 0.008);
  EXPECT_EQ(sizer.next(), 64000u);
  sizer.finished(64000, 0.064);
  EXPECT_EQ(sizer.next(), 100000u);  // at the target
  sizer.finished(100000, 0.1);
  EXPECT_EQ(sizer.next(), 100000u);  // and stays there
  sizer.finished(100000, 10.0);  // the device got 100x slower: 4x smaller at most
  EXPECT_EQ(sizer.next(), 25000u);
  for (int i = 0; i < 20; ++i) sizer.finished(sizer.next(), 10.0);
  EXPECT_EQ(sizer.next(), 100u);  // never below the least
  for (int i = 0; i < 20; ++i) sizer.finished(sizer.next(), 1e-6);
  EXPECT_EQ(sizer.next(), 1'000'000u);  // nor above the most
  sizer.finished(1000, 0.0);  // too fast to measure: grows
  EXPECT_EQ(sizer.next(), 8000u);
}

TEST(TilingTest, TheFirstSizeIsKeptWithinTheBounds) {
  EXPECT_EQ(SubmissionSizer(10, 100, 1000, 0.1).next(), 100u);
  EXPECT_EQ(SubmissionSizer(5000, 100, 1000, 0.1).next(), 1000u);
  SubmissionSizer slot_first(5000, 2000, 1000, 0.1);  // a least past the slot: the slot wins
  EXPECT_EQ(slot_first.next(), 1000u);
  slot_first.finished(1000, 100.0);
  EXPECT_EQ(slot_first.next(), 1000u);
}

}  // namespace
}  // namespace vkray::gpu
