// Renders a scene with the GPU path (on the fixture's device, validation on) and with the CPU
// reference, and compares them, as `vkray parity` does (compare/parity.h).
#pragma once

#include <ostream>
#include <string>

#include "compare/parity.h"
#include "support/gpu_fixture.h"
#include "support/temp_dir.h"

namespace vkray {
// For test names and messages.
inline void PrintTo(InlineScene policy, std::ostream* os) {
  *os << (policy == InlineScene::always ? "always" : policy == InlineScene::never ? "never" : "automatic");
}
}  // namespace vkray

namespace vkray::test {

class ParityTest : public GpuTest {
 protected:
  ParityResult run(const Scene& scene, const ImageSettings& image, InlineScene inline_scene = InlineScene::automatic);
  // Fails the test when the tolerance does not hold, naming the metrics and the heatmap written to
  // <build>/tests/parity-failures/<name>.png.
  void expect_parity(const ParityResult& run, const std::string& name);
};

// Parity with a copy of the shaders in which one line is broken on purpose (`good` replaced by
// `bad` in `file`), to show that parity notices that mistake. Fails at SetUp when `good` is no
// longer in the file, so that the test never passes by breaking nothing.
class BrokenShaderParityTest : public ParityTest {
 protected:
  BrokenShaderParityTest(const std::string& file, const std::string& good, const std::string& bad);
  void SetUp() override;
  std::filesystem::path shader_dir() const override { return shaders_.path(); }
  // Fails the test unless parity fails on checks/<name>.json at 96 x 64, 4 spp.
  void expect_caught_on_check(const std::string& name);

 private:
  TempDir shaders_;
  std::string file_, good_;
  bool broken_ = false;
};

}  // namespace vkray::test
