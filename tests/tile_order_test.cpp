// The order in which a dispatch's workgroup rows cover a tile (TileConstants::row_stride): a
// permutation, and one that gives every contiguous share of the dispatch (what llvmpipe hands each
// of its threads) rows from all over the tile.
#include <cmath>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

#include "packing/scene_packing.h"

namespace vkray::gpu {
namespace {

TEST(TileOrderTest, RowStrideIsAPermutation) {
  for (uint32_t rows = 1; rows <= 3000; ++rows) {
    const uint32_t stride = row_stride(rows);
    ASSERT_GE(stride, 1u) << rows << " rows";
    ASSERT_EQ(std::gcd(stride, rows), 1u) << rows << " rows, stride " << stride;
    std::vector<bool> covered(rows, false);
    for (uint32_t r = 0; r < rows; ++r) {
      const uint32_t row = uint32_t(uint64_t(r) * stride % rows);
      ASSERT_FALSE(covered[row]) << rows << " rows: row " << row << " twice";
      covered[row] = true;
    }
  }
}

TEST(TileOrderTest, EachShareOfTheDispatchSpansTheTile) {
  // Split the dispatch into 2, 3 or 4 contiguous shares; each share's rows must fall about evenly
  // into the tile's top and bottom halves (in dispatch order they would all be in one): within
  // 3 rows + 5% of the share of an even split (the worst case, 56 rows in 2 shares, is 10 of 28).
  for (uint32_t rows = 16; rows <= 2048; ++rows) {
    const uint32_t stride = row_stride(rows);
    for (uint32_t shares = 2; shares <= 4; ++shares) {
      for (uint32_t share = 0; share < shares; ++share) {
        const uint32_t begin = rows * share / shares, end = rows * (share + 1) / shares;
        uint32_t top = 0;
        for (uint32_t r = begin; r < end; ++r) top += uint64_t(r) * stride % rows < rows / 2;
        const double size = double(end - begin);
        EXPECT_LE(std::abs(double(top) - size / 2), 3.0 + 0.05 * size)
            << rows << " rows, share " << share << " of " << shares << ": " << top << " of " << size << " in the top half";
      }
    }
  }
}

}  // namespace
}  // namespace vkray::gpu
