#include "support/parity_run.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>

#include "image/image.h"
#include "image/image_file.h"
#include "load/scene_loader.h"

namespace vkray::test {

ParityResult ParityTest::run(const Scene& scene, const ImageSettings& image, InlineScene inline_scene) {
  RenderOptions options;
  options.inline_scene = inline_scene;
  return compare_with_reference(session(), std::make_shared<const Scene>(scene), with_image(options, image));
}

void ParityTest::expect_parity(const ParityResult& run, const std::string& name) {
  const ParityMetrics& m = run.metrics;
  if (m.pass) return;
  const std::filesystem::path dir = VKRAY_PARITY_OUTPUT_DIR;
  std::filesystem::create_directories(dir);
  int max_steps = 0;
  write_image(difference_heatmap(run.gpu.image, run.cpu.image, max_steps), dir / (name + ".png"));
  ADD_FAILURE() << name << ": parity tolerance (" << describe_tolerance(run.tolerance) << ") does not hold:\n"
                << "  " << describe_metrics(m) << "\n"
                << "  heatmap (1 to " << max_steps << " steps): " << (dir / (name + ".png")).string();
}

BrokenShaderParityTest::BrokenShaderParityTest(const std::string& file, const std::string& good, const std::string& bad)
    : file_(file), good_(good) {
  std::filesystem::copy(VKRAY_SHADER_DIR, shaders_.path(), std::filesystem::copy_options::recursive);
  std::ifstream in(shaders_.path() / file);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  const size_t at = text.find(good);
  if (at == std::string::npos) return;
  std::ofstream(shaders_.path() / file) << text.replace(at, good.size(), bad);
  broken_ = true;
}

void BrokenShaderParityTest::SetUp() {
  ParityTest::SetUp();
  if (!broken_) FAIL() << file_ << " no longer holds \"" << good_ << "\": the test breaks nothing";
}

void BrokenShaderParityTest::expect_caught_on_check(const std::string& name) {
  const Scene scene = load_scene(std::filesystem::path(VKRAY_CHECK_DIR) / (name + ".json"));
  const ParityResult r = run(scene, {96, 64, 4});
  EXPECT_FALSE(r.metrics.pass) << name << ": " << describe_metrics(r.metrics);
}

}  // namespace vkray::test
