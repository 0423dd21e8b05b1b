// A GoogleTest fixture for tests that use the device: validation on, and any validation message
// (during the test or while the device is torn down) fails the test.
#pragma once

#include <memory>

#include <gtest/gtest.h>

#include "gpu/context.h"

namespace vkray::test {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  gpu::Context& ctx() { return *ctx_; }

 private:
  std::shared_ptr<gpu::ValidationLog> log_;
  std::unique_ptr<gpu::Context> ctx_;
};

}  // namespace vkray::test
