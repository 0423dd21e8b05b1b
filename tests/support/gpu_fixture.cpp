#include "support/gpu_fixture.h"

namespace vkray::test {

void GpuTest::SetUp() {
  log_ = std::make_shared<gpu::ValidationLog>();
  gpu::ContextOptions options;
  options.validation = true;
  options.validation_log = log_;
  ctx_ = std::make_unique<gpu::Context>(options);  // no device is a failure, never a skip
}

void GpuTest::TearDown() {
  ctx_.reset();
  for (const auto& message : log_->messages()) ADD_FAILURE() << message;
}

}  // namespace vkray::test
