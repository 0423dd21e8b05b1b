// Renders a scene with the GPU path (on the fixture's device, validation on) and with the CPU
// reference, and compares them, as `vkray parity` does (session/parity.h).
#pragma once

#include <ostream>
#include <string>

#include "session/parity.h"
#include "support/gpu_fixture.h"

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

}  // namespace vkray::test
