// Checked size arithmetic: exact below 2^64, an input error (exit 1) naming what was being sized above.
#include <cstdint>

#include <gtest/gtest.h>

#include "base/checked.h"

namespace vkray {
namespace {

TEST(CheckedTest, ExactUpToTheLimitAndAnErrorBeyond) {
  EXPECT_EQ(checked_mul(16384, 16384, "x"), 268435456u);
  EXPECT_EQ(checked_mul(UINT64_MAX, 1, "x"), UINT64_MAX);
  EXPECT_EQ(checked_add(UINT64_MAX - 1, 1, "x"), UINT64_MAX);
  EXPECT_THROW(checked_add(UINT64_MAX, 1, "x"), LimitError);
  try {
    checked_mul(uint64_t(1) << 32, uint64_t(1) << 32, "output image");
    ADD_FAILURE() << "no error";
  } catch (const LimitError& e) {
    EXPECT_STREQ(e.what(), "output image: size overflows 64 bits");
  }
}

}  // namespace
}  // namespace vkray
