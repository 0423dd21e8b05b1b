#include "cli/commands.h"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "bvh/bvh.h"
#include "cpu/reference.h"
#include "base/errors.h"
#include "gpu/context.h"
#include "gpu/renderer.h"
#include "gpu/shader_compiler.h"
#include "image/image.h"
#include "image/parity_metrics.h"
#include "session/paths.h"
#include "scene/scene.h"
#include "cli/stop_signals.h"
#include "base/timing.h"

namespace vkray {
namespace {

std::string format_rate(uint64_t rays, double seconds) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2f Mrays/s", seconds > 0 ? double(rays) / seconds * 1e-6 : 0.0);
  return buffer;
}

// Shows progress once a render has taken about a second: in place on a terminal, else one line a
// second.
class Progress {
 public:
  Progress(bool enabled, const char* what) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1), what_(what) {}
  ~Progress() {
    if (shown_ && tty_) std::cerr << "\n";
  }
  void update(uint32_t done, uint32_t total, const char* unit) {
    const double elapsed = ms_since(start_);
    if (!enabled_ || elapsed < 1000.0 || (done == total && !shown_)) return;
    if (!tty_ && elapsed - last_ < 1000.0 && done != total) return;
    last_ = elapsed;
    shown_ = true;
    std::cerr << (tty_ ? "\r" : "") << "vkray: " << what_ << " " << (100 * uint64_t(done) / total) << "% (" << done
              << "/" << total << " " << unit << ")" << (tty_ ? "" : "\n") << std::flush;
  }

 private:
  bool enabled_, tty_, shown_ = false;
  const char* what_;
  Clock::time_point start_ = Clock::now();
  double last_ = 0;
};

struct LoadedScene {
  std::filesystem::path file;
  Scene scene;
  ImageSettings image;
  double load_ms = 0;
};

LoadedScene load(const RenderFlags& flags) {
  const auto start = Clock::now();
  LoadedScene loaded;
  loaded.file = flags.scene.empty() ? default_scene() : flags.scene;
  loaded.scene = load_scene(loaded.file);
  for (const auto& warning : loaded.scene.warnings) std::cerr << "vkray: warning: " << warning << "\n";
  loaded.image = image_settings(loaded.scene, flags);
  loaded.load_ms = ms_since(start);
  return loaded;
}

}  // namespace

void check_output_path(const std::filesystem::path& output) {
  if (!is_supported_image_path(output)) throw OutputError(output.string() + ": unknown image type (expected .png or .pfm)");
  const auto dir = output.has_parent_path() ? output.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) throw OutputError(output.string() + ": folder " + dir.string() + " does not exist");
}

namespace {

struct GpuRun {
  Image image;
  gpu::RenderStats stats;
  double compile_ms = 0;
  std::string device;
};

// Creates the device, compiles the shader, renders, and tears the device down again. The device
// lives only inside: its teardown can itself raise validation messages (leaked objects, say), and
// those must fail the command before anything is written.
// `bvh`: one already built for the scene (parity shares it with the CPU reference); null builds one.
GpuRun render_gpu(const LoadedScene& loaded, const RenderFlags& flags, const std::function<void(const std::string&)>& log,
                  bool show_progress, const StopSignals* stop = nullptr, const Bvh* bvh = nullptr) {
  auto validation_log = std::make_shared<gpu::ValidationLog>();
  GpuRun run;
  {
    gpu::ContextOptions options;
    options.validation = flags.validate;
    options.device = flags.device;
    options.validation_log = validation_log;
    gpu::Context ctx(options);
    run.device = ctx.device_name() + " (" + ctx.driver_name() + ")";
    log("device " + run.device + (flags.validate ? ", validation on" : ""));
    const auto start = Clock::now();
    const std::filesystem::path shader_dir = flags.shader_dir.empty() ? default_shader_dir() : flags.shader_dir;
    const gpu::CompiledShader shader = gpu::compile_compute_shader(shader_dir / "trace.comp", {shader_dir});
    const gpu::TracePipeline pipeline(ctx, shader_dir, shader);
    run.compile_ms = ms_since(start);
    const gpu::GpuScene gpu_scene(ctx, loaded.scene, bvh);
    // The scene's pipeline variant compiled now, so that compile_ms counts it (a small scene's own
    // code is compiled only now that the scene is packed).
    const auto variant_start = Clock::now();
    pipeline.pipeline(gpu::shader_variant(gpu_scene, loaded.image, flags.inline_scene));
    ctx.check_validation("pipeline creation");
    run.compile_ms += ms_since(variant_start);

    Progress progress(show_progress, "tracing");
    gpu::RenderOptions render_options;
    render_options.progress = [&](uint32_t done, uint32_t total) { progress.update(done, total, "tiles"); };
    render_options.tile_timeout = std::chrono::milliseconds(flags.tile_timeout_ms);
    render_options.inline_scene = flags.inline_scene;
    if (stop) render_options.cancel = [stop] { return stop->pending(); };
    try {
      run.image = gpu::render(ctx, pipeline, gpu_scene, loaded.image, render_options, &run.stats);
      run.stats.bvh_seconds = gpu_scene.bvh_seconds();
      run.stats.upload_seconds += gpu_scene.upload_seconds();
    } catch (const TimeoutError& e) {
      // Work may still be running on the device: destroying what it uses could hang or worse, so
      // report and leave at once. Nothing has been written.
      std::cerr << "vkray: device error: " << e.what() << "\n";
      std::cerr.flush();
      std::_Exit(kExitDevice);
    }
  }
  if (validation_log->count() > 0)
    throw DeviceError(std::to_string(validation_log->count()) + " validation message(s); the first:\n  " +
                      validation_log->messages().front());
  return run;
}

cpu::ReferenceResult render_cpu(const LoadedScene& loaded, const RenderFlags& flags, bool show_progress,
                                const Bvh* bvh = nullptr) {
  Progress progress(show_progress, "CPU reference");
  cpu::ReferenceOptions options;
  options.threads = flags.threads;
  options.bvh = bvh;
  options.progress = [&](uint32_t done, uint32_t total) { progress.update(done, total, "rows"); };
  return cpu::render_reference(loaded.scene, loaded.image, options);
}

unsigned thread_count(const RenderFlags& flags) {
  return flags.threads ? flags.threads : std::max(1u, std::thread::hardware_concurrency());
}

std::string describe(const LoadedScene& loaded) {
  const Scene& s = loaded.scene;
  return loaded.file.string() + ": " + std::to_string(s.triangles.size()) + " triangles, " +
         std::to_string(s.spheres.size()) + " spheres, " + std::to_string(s.lights.size()) + " lights; " +
         std::to_string(loaded.image.width) + "x" + std::to_string(loaded.image.height) + ", " +
         std::to_string(loaded.image.samples_per_pixel) + " spp";
}

}  // namespace

ImageSettings image_settings(const Scene& scene, const RenderFlags& flags) {
  ImageSettings image = scene.image;
  if (flags.width) image.width = *flags.width;
  if (flags.height) image.height = *flags.height;
  if (flags.spp) image.samples_per_pixel = *flags.spp;
  return image;
}

int run_render(const RenderCommand& cmd) {
  const StopSignals stop;  // Ctrl-C stops the render between tiles, not in the middle of a Vulkan call
  const auto total_start = Clock::now();
  auto log = [&](const std::string& line) {
    if (!cmd.quiet) std::cerr << "vkray: " << line << "\n";
  };
  const LoadedScene loaded = load(cmd.flags);
  const std::filesystem::path output =
      cmd.output.empty() ? std::filesystem::path(loaded.scene.name + ".png") : cmd.output;
  check_output_path(output);

  Image image;
  std::string phases;
  uint64_t rays = 0;
  double trace_seconds = 0;
  if (cmd.renderer == "cpu") {
    log("renderer CPU reference, " + std::to_string(thread_count(cmd.flags)) + " threads");
    log(describe(loaded));
    cpu::ReferenceResult result = render_cpu(loaded, cmd.flags, !cmd.quiet);
    image = std::move(result.image);
    rays = result.rays;
    trace_seconds = result.seconds;
    phases = "load " + format_ms(loaded.load_ms) + " | trace " + format_ms(result.seconds * 1e3);
  } else {
    log(describe(loaded));
    GpuRun run;
    try {
      run = render_gpu(loaded, cmd.flags, log, !cmd.quiet, &stop);
    } catch (const Cancelled&) {
      std::cerr << "vkray: interrupted; no image written\n";
      return kExitInterrupted;
    }
    image = std::move(run.image);
    rays = run.stats.rays;
    trace_seconds = run.stats.trace_seconds;
    phases = "load " + format_ms(loaded.load_ms) + " | compile " + format_ms(run.compile_ms) + " | upload " +
             format_ms(run.stats.upload_seconds * 1e3) + " | trace " + format_ms(run.stats.trace_seconds * 1e3) + " (" +
             std::to_string(run.stats.tiles) + (run.stats.tiles == 1 ? " tile" : " tiles") +
             (run.stats.inline_scene ? ", scene compiled into the shader" : "") + ") | read back " +
             format_ms(run.stats.readback_seconds * 1e3);
  }

  const auto start = Clock::now();
  write_image(image, output);
  log(phases + " | write " + format_ms(ms_since(start)));
  log(std::to_string(rays) + " rays (camera + shadow), " + format_rate(rays, trace_seconds) + "; total " +
      format_ms(ms_since(total_start)));
  log("wrote " + output.string());
  return kExitOk;
}

int run_parity(const ParityCommand& cmd) {
  auto log = [&](const std::string& line) {
    if (!cmd.json) std::cerr << "vkray: " << line << "\n";
  };
  const LoadedScene loaded = load(cmd.flags);
  if (!cmd.diff.empty()) check_output_path(cmd.diff);
  log(describe(loaded));

  const Bvh bvh = build_bvh(primitive_boxes(loaded.scene));  // one hierarchy, traversed by both
  const GpuRun gpu_run = render_gpu(loaded, cmd.flags, log, !cmd.json, nullptr, &bvh);
  const cpu::ReferenceResult reference = render_cpu(loaded, cmd.flags, !cmd.json, &bvh);
  const ParityTolerance tolerance;
  const ParityMetrics m = compare_images(gpu_run.image, reference.image, reference.signatures, tolerance);

  // A PNG shows what a person can see (8-bit steps); a PFM holds the raw linear differences.
  int max_steps = 0;
  const bool diff_is_pfm = cmd.diff.extension() == ".pfm";
  if (!cmd.diff.empty())
    write_image(diff_is_pfm ? absolute_difference(gpu_run.image, reference.image)
                            : difference_heatmap(gpu_run.image, reference.image, max_steps),
                cmd.diff);

  const glm::vec3 worst_gpu = gpu_run.image.at(m.worst_x, m.worst_y), worst_cpu = reference.image.at(m.worst_x, m.worst_y);
  if (cmd.json) {
    nlohmann::json j = {
        {"scene", loaded.file.string()},
        {"width", m.width},
        {"height", m.height},
        {"samples_per_pixel", loaded.image.samples_per_pixel},
        {"device", gpu_run.device},
        {"gpu_trace_seconds", gpu_run.stats.trace_seconds},
        {"cpu_trace_seconds", reference.seconds},
        {"cpu_threads", thread_count(cmd.flags)},
        {"rays", reference.rays},
        {"max_abs_diff", m.max_abs},
        {"mean_abs_diff", m.mean_abs},
        {"psnr_db", std::isinf(m.psnr) ? nlohmann::json(nullptr) : nlohmann::json(m.psnr)},
        {"share_over_1", m.share_over_1()},
        {"share_over_2", m.share_over_2()},
        {"pixels_over_1", m.over_1},
        {"pixels_over_2", m.over_2},
        {"edge_pixels", m.edge_pixels},
        {"edge_pixels_over_1", m.edge_over_1},
        {"interior_pixels_over_1", m.interior_over_1},
        {"interior_pixels_over_2", m.interior_over_2},
        {"worst_pixel", {m.worst_x, m.worst_y}},
        {"worst_gpu", {worst_gpu.r, worst_gpu.g, worst_gpu.b}},
        {"worst_cpu", {worst_cpu.r, worst_cpu.g, worst_cpu.b}},
        {"tolerance", describe_tolerance(tolerance)},
        {"pass", m.pass},
    };
    if (!cmd.diff.empty()) {
      j["diff_image"] = cmd.diff.string();
      if (!diff_is_pfm) j["diff_max_steps"] = max_steps;
    }
    std::cout << j.dump() << "\n";
  } else {
    char line[512];
    std::printf("GPU %s in %s (%s); CPU reference (%u threads) in %s (%s): CPU/GPU time %.1fx\n",
                gpu_run.device.c_str(), format_ms(gpu_run.stats.trace_seconds * 1e3).c_str(),
                format_rate(gpu_run.stats.rays, gpu_run.stats.trace_seconds).c_str(), thread_count(cmd.flags),
                format_ms(reference.seconds * 1e3).c_str(), format_rate(reference.rays, reference.seconds).c_str(),
                reference.seconds / gpu_run.stats.trace_seconds);
    std::snprintf(line, sizeof line, "max |GPU - CPU| %.3g (linear) at pixel (%u, %u): GPU (%.6g, %.6g, %.6g), CPU (%.6g, %.6g, %.6g)",
                  m.max_abs, m.worst_x, m.worst_y, worst_gpu.r, worst_gpu.g, worst_gpu.b, worst_cpu.r, worst_cpu.g, worst_cpu.b);
    std::printf("%s\n", line);
    std::printf("mean |GPU - CPU| %.3g (linear); PSNR %s\n", m.mean_abs,
                std::isinf(m.psnr) ? "inf (identical after clamping)" : (std::to_string(m.psnr).substr(0, 5) + " dB").c_str());
    std::printf("8-bit sRGB differences: > 1 on %llu pixels (%.4f%%), > 2 on %llu (%.4f%%); away from edges: > 1 on %llu, > 2 on %llu\n",
                static_cast<unsigned long long>(m.over_1), m.share_over_1() * 100, static_cast<unsigned long long>(m.over_2),
                m.share_over_2() * 100, static_cast<unsigned long long>(m.interior_over_1),
                static_cast<unsigned long long>(m.interior_over_2));
    std::printf("silhouette and shadow edge pixels: %llu (%.2f%% of the image), of which %llu (%.3f%%) differ by > 1\n",
                static_cast<unsigned long long>(m.edge_pixels), 100.0 * double(m.edge_pixels) / double(m.pixels()),
                static_cast<unsigned long long>(m.edge_over_1), 100.0 * m.edge_share_over_1());
    if (!cmd.diff.empty() && diff_is_pfm)
      std::printf("difference image: %s (|GPU - CPU| per channel, linear)\n", cmd.diff.string().c_str());
    else if (!cmd.diff.empty())
      std::printf("difference heatmap: %s (grey: same 8-bit sRGB values; dark purple = 1 step, pale yellow = %d steps)\n",
                  cmd.diff.string().c_str(), max_steps);
    std::printf("tolerance (%s): %s\n", describe_tolerance(tolerance).c_str(), m.pass ? "PASS" : "FAIL");
  }
  return m.pass ? kExitOk : kExitParityFailed;
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
