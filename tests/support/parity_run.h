// Renders a scene with the GPU path (on the fixture's device, validation on) and with the CPU
// reference, and compares them, as `vkray parity` does.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "cpu/reference.h"
#include "gpu/renderer.h"
#include "parity.h"
#include "support/gpu_fixture.h"

namespace vkray::test {

struct ParityRun {
  Image gpu;
  cpu::ReferenceResult cpu;
  ParityMetrics metrics;
};

class ParityTest : public GpuTest {
 protected:
  void TearDown() override;
  ParityRun run(const Scene& scene, const ImageSettings& image);
  // Fails the test when the tolerance does not hold, naming the metrics and the heatmap written to
  // <build>/tests/parity-failures/<name>.png.
  void expect_parity(const ParityRun& run, const std::string& name);

 private:
  std::unique_ptr<gpu::TracePipeline> pipeline_;
};

}  // namespace vkray::test
