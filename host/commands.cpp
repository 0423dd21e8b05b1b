#include "commands.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>

#include "errors.h"
#include "gpu/context.h"
#include "gpu/renderer.h"
#include "gpu/shader_compiler.h"
#include "image.h"
#include "paths.h"
#include "scene.h"

namespace vkray {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string format_ms(double ms) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, ms < 10 ? "%.2f ms" : "%.0f ms", ms);
  return buffer;
}

// Shows tile progress once a render has taken about a second: in place on a terminal, else one
// line a second.
class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}
  ~Progress() {
    if (shown_ && tty_) std::cerr << "\n";
  }
  void update(uint32_t done, uint32_t total) {
    const double elapsed = ms_since(start_);
    if (!enabled_ || elapsed < 1000.0 || (done == total && !shown_)) return;
    if (!tty_ && elapsed - last_ < 1000.0 && done != total) return;
    last_ = elapsed;
    shown_ = true;
    std::cerr << (tty_ ? "\r" : "") << "vkray: tracing " << (100 * done / total) << "% (" << done << "/" << total
              << " tiles)" << (tty_ ? "" : "\n") << std::flush;
  }

 private:
  bool enabled_, tty_, shown_ = false;
  Clock::time_point start_ = Clock::now();
  double last_ = 0;
};

}  // namespace

int run_render(const RenderCommand& cmd) {
  const auto total_start = Clock::now();
  auto log = [&](const std::string& line) {
    if (!cmd.quiet) std::cerr << "vkray: " << line << "\n";
  };

  // ---- load ----
  auto start = Clock::now();
  const std::filesystem::path scene_file = cmd.scene.empty() ? default_scene() : cmd.scene;
  const Scene scene = load_scene(scene_file);
  for (const auto& warning : scene.warnings) std::cerr << "vkray: warning: " << warning << "\n";
  ImageSettings image = scene.image;
  if (cmd.width) image.width = *cmd.width;
  if (cmd.height) image.height = *cmd.height;
  if (cmd.spp) image.samples_per_pixel = *cmd.spp;
  const std::filesystem::path output = cmd.output.empty() ? std::filesystem::path(scene.name + ".png") : cmd.output;
  if (!is_supported_image_path(output))
    throw OutputError(output.string() + ": unknown image type (expected .png or .pfm)");
  const auto out_dir = output.has_parent_path() ? output.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(out_dir, ec)) throw OutputError(output.string() + ": folder " + out_dir.string() + " does not exist");
  const double load_ms = ms_since(start);

  // ---- device, shader, render ----
  // The device lives in this scope only: its teardown can itself raise validation messages (leaked
  // objects, say), and those must fail the command before an image is written.
  auto validation_log = std::make_shared<gpu::ValidationLog>();
  Image result;
  gpu::RenderStats stats;
  double compile_ms = 0;
  {
    gpu::ContextOptions options;
    options.validation = cmd.validate;
    options.device = cmd.device;
    options.validation_log = validation_log;
    gpu::Context ctx(options);
    log("device " + ctx.device_name() + " (" + ctx.driver_name() + ")" + (cmd.validate ? ", validation on" : ""));
    start = Clock::now();
    const std::filesystem::path shader_dir = cmd.shader_dir.empty() ? default_shader_dir() : cmd.shader_dir;
    const gpu::CompiledShader shader = gpu::compile_compute_shader(shader_dir / "trace.comp", {shader_dir});
    const gpu::TracePipeline pipeline(ctx, shader.spirv);
    ctx.check_validation("pipeline creation");
    compile_ms = ms_since(start);
    log(scene_file.string() + ": " + std::to_string(scene.triangles.size()) + " triangles, " +
        std::to_string(scene.spheres.size()) + " spheres, " + std::to_string(scene.lights.size()) + " lights; " +
        std::to_string(image.width) + "x" + std::to_string(image.height) + ", " +
        std::to_string(image.samples_per_pixel) + " spp");

    Progress progress(!cmd.quiet);
    gpu::RenderOptions render_options;
    render_options.progress = [&](uint32_t done, uint32_t total) { progress.update(done, total); };
    result = gpu::render(ctx, pipeline, scene, image, render_options, &stats);
  }
  if (validation_log->count() > 0)
    throw DeviceError(std::to_string(validation_log->count()) + " validation message(s); the first:\n  " +
                      validation_log->messages().front());

  // ---- write ----
  start = Clock::now();
  write_image(result, output);
  const double write_ms = ms_since(start);

  log("load " + format_ms(load_ms) + " | compile " + format_ms(compile_ms) + " | upload " +
      format_ms(stats.upload_seconds * 1e3) + " | trace " + format_ms(stats.trace_seconds * 1e3) + " (" +
      std::to_string(stats.tiles) + (stats.tiles == 1 ? " tile" : " tiles") + ") | read back " +
      format_ms(stats.readback_seconds * 1e3) + " | write " + format_ms(write_ms));
  char rate[128];
  std::snprintf(rate, sizeof rate, "%llu rays (camera + shadow), %.2f Mrays/s; total %s",
                static_cast<unsigned long long>(stats.rays), double(stats.rays) / stats.trace_seconds * 1e-6,
                format_ms(ms_since(total_start)).c_str());
  log(rate);
  log("wrote " + output.string());
  return kExitOk;
}

int run_devices() {
  const auto devices = gpu::list_devices();
  if (devices.empty()) {
    std::cout << "no Vulkan devices found\n";
    return kExitDevice;
  }
  for (const auto& d : devices) {
    std::cout << d.index << ": " << d.name << "\n"
              << "   type " << d.type << ", Vulkan " << d.api_version << ", driver " << d.driver << "\n"
              << "   compute queue " << (d.has_compute_queue ? "yes" : "NO") << ", max workgroup invocations "
              << d.max_workgroup_invocations << "\n"
              << "   max texel buffer elements " << d.max_texel_buffer_elements << ", max storage buffer range "
              << d.max_storage_buffer_range << " bytes, device-local memory " << (d.device_local_bytes >> 20)
              << " MiB\n";
  }
  return kExitOk;
}

}  // namespace vkray
