#include "support/parity_run.h"

#include "bvh/bvh.h"
#include "gpu/shader_compiler.h"

namespace vkray::test {

void ParityTest::TearDown() {
  pipeline_.reset();
  GpuTest::TearDown();
}

ParityRun ParityTest::run(const Scene& scene, const ImageSettings& image, gpu::InlineScene inline_scene) {
  if (!pipeline_) {
    const std::filesystem::path dir = VKRAY_SHADER_DIR;
    pipeline_ = std::make_unique<gpu::TracePipeline>(ctx(), dir, gpu::compile_compute_shader(dir / "trace.comp", {dir}));
  }
  ParityRun result;
  const Bvh bvh = build_bvh(primitive_boxes(scene));  // one hierarchy, traversed by both renderers
  gpu::RenderOptions options;
  options.inline_scene = inline_scene;
  gpu::RenderStats stats;
  result.gpu = gpu::render(ctx(), *pipeline_, gpu::GpuScene(ctx(), scene, &bvh), image, options, &stats);
  result.inline_scene = stats.inline_scene;
  cpu::ReferenceOptions reference_options;
  reference_options.bvh = &bvh;
  result.cpu = cpu::render_reference(scene, image, reference_options);
  result.metrics = compare_images(result.gpu, result.cpu.image, result.cpu.signatures);
  return result;
}

void ParityTest::expect_parity(const ParityRun& run, const std::string& name) {
  const ParityMetrics& m = run.metrics;
  if (m.pass) return;
  const std::filesystem::path dir = VKRAY_PARITY_OUTPUT_DIR;
  std::filesystem::create_directories(dir);
  int max_steps = 0;
  write_image(difference_heatmap(run.gpu, run.cpu.image, max_steps), dir / (name + ".png"));
  ADD_FAILURE() << name << ": parity tolerance (" << describe_tolerance({}) << ") does not hold:\n"
                << "  > 1 step on " << m.interior_over_1 << " pixels away from edges and on " << m.edge_over_1 << " of "
                << m.edge_pixels << " edge pixels; > 2 steps on " << m.over_2 << "; max |diff| " << m.max_abs << " at ("
                << m.worst_x << ", " << m.worst_y << ")\n"
                << "  heatmap (1 to " << max_steps << " steps): " << (dir / (name + ".png")).string();
}

}  // namespace vkray::test
