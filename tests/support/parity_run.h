// Renders a scene with the GPU path (on the fixture's device, validation on) and with the CPU
// reference, and compares them, as `vkray parity` does.
#pragma once

#include <filesystem>
#include <memory>
#include <ostream>
#include <string>

#include "cpu/reference.h"
#include "gpu/renderer.h"
#include "image/parity_metrics.h"
#include "support/gpu_fixture.h"

namespace vkray::gpu {
// For test names and messages.
inline void PrintTo(InlineScene policy, std::ostream* os) {
  *os << (policy == InlineScene::always ? "always" : policy == InlineScene::never ? "never" : "automatic");
}
}  // namespace vkray::gpu

namespace vkray::test {

struct ParityRun {
  Image gpu;
  cpu::ReferenceResult cpu;
  ParityMetrics metrics;
  bool inline_scene = false;  // the GPU path traced the scene compiled into the shader
};

class ParityTest : public GpuTest {
 protected:
  void TearDown() override;
  ParityRun run(const Scene& scene, const ImageSettings& image,
                gpu::InlineScene inline_scene = gpu::InlineScene::automatic);
  // Fails the test when the tolerance does not hold, naming the metrics and the heatmap written to
  // <build>/tests/parity-failures/<name>.png.
  void expect_parity(const ParityRun& run, const std::string& name);

 private:
  std::unique_ptr<gpu::TracePipeline> pipeline_;
};

}  // namespace vkray::test
