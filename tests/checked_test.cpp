// Checked size arithmetic: exact below 2^64, an error naming what was being sized above.
#include <cstdint>
#include <stdexcept>

#include <gtest/gtest.h>

#include "base/checked.h"

namespace vkray {
namespace {

TEST(CheckedTest, ExactUpToTheLimitAndAnErrorBeyond) {
  EXPECT_EQ(checked_mul(16384, 16384, "x"), 268435456u);
  EXPECT_EQ(checked_mul(UINT64_MAX, 1, "x"), UINT64_MAX);
  EXPECT_EQ(checked_add(UINT64_MAX - 1, 1, "x"), UINT64_MAX);
  EXPECT_THROW(checked_add(UINT64_MAX, 1, "x"), std::length_error);
  try {
    checked_mul(uint64_t(1) << 32, uint64_t(1) << 32, "output image");
    ADD_FAILURE() << "no error";
  } catch (const std::length_error& e) {
    EXPECT_STREQ(e.what(), "output image: size overflows 64 bits");
  }
}

}  // namespace
}  // namespace vkray
