// `vkray parity`: a scene rendered on the GPU and with the CPU reference, the difference measured
// against the tolerance, printed as text or one JSON object.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <optional>

#include <nlohmann/json.hpp>

#include "base/errors.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "compare/parity_report.h"
#include "cli/report.h"
#include "image/image.h"
#include "image/image_file.h"
#include "compare/parity.h"
#include "session/session.h"
#include "session/version.h"
#include "load/scene_loader.h"

namespace vkray::cli {
namespace {

struct ParityArgs {
  SceneFlags scene;
  DeviceFlags device;
  GpuFlags gpu;
  CpuFlags cpu;
  std::filesystem::path diff;  // where to write the difference heatmap; empty: none
  bool json = false;
};

void print_text(const ParityResult& r, const std::string& device, const std::filesystem::path& diff, bool diff_is_pfm,
                int max_steps) {
  const ParityMetrics& m = r.metrics;
  const RenderStats &gpu = r.gpu.stats, &cpu = r.cpu.stats;
  const glm::vec3 worst_gpu = r.gpu.image.at(m.worst_x, m.worst_y), worst_cpu = r.cpu.image.at(m.worst_x, m.worst_y);
  std::printf("GPU %s in %s (%s); CPU reference (%u threads) in %s (%s): CPU/GPU time %.1fx\n", device.c_str(),
              format_ms(gpu.trace_seconds * 1e3).c_str(), format_rate(gpu.rays, gpu.trace_seconds).c_str(), cpu.threads,
              format_ms(cpu.trace_seconds * 1e3).c_str(), format_rate(cpu.rays, cpu.trace_seconds).c_str(),
              cpu.trace_seconds / gpu.trace_seconds);
  std::printf("max |GPU - CPU| %.3g (linear) at pixel (%u, %u): GPU (%.6g, %.6g, %.6g), CPU (%.6g, %.6g, %.6g)\n",
              m.max_abs, m.worst_x, m.worst_y, worst_gpu.r, worst_gpu.g, worst_gpu.b, worst_cpu.r, worst_cpu.g, worst_cpu.b);
  std::printf("mean |GPU - CPU| %.3g (linear); PSNR %s; the image means differ by %.3g%% (the worst channel)\n", m.mean_abs,
              std::isinf(m.psnr) ? "inf (identical after clamping)" : (std::to_string(m.psnr).substr(0, 5) + " dB").c_str(),
              m.mean_relative * 100);
  if (m.non_finite > 0) std::printf("%llu GPU pixels are NaN or infinite\n", static_cast<unsigned long long>(m.non_finite));
  std::printf("8-bit sRGB differences: > 1 on %llu pixels (%.4f%%), > 2 on %llu (%.4f%%); away from edges: > 1 on %llu, > 2 on %llu\n",
              static_cast<unsigned long long>(m.over_1), m.share_over_1() * 100, static_cast<unsigned long long>(m.over_2),
              m.share_over_2() * 100, static_cast<unsigned long long>(m.interior_over_1),
              static_cast<unsigned long long>(m.interior_over_2));
  std::printf("silhouette and shadow edge pixels: %llu (%.2f%% of the image), of which %llu (%.3f%%) differ by > 1\n",
              static_cast<unsigned long long>(m.edge_pixels), 100.0 * double(m.edge_pixels) / double(m.pixels()),
              static_cast<unsigned long long>(m.edge_over_1), 100.0 * m.edge_share_over_1());
  if (m.aovs_compared) {
    std::string by_pass;
    for (size_t pass = 0; pass < kAllAovs.size(); ++pass)
      by_pass += std::string(pass ? ", " : "") + aov_name(kAllAovs[pass]) + " " + std::to_string(m.aov_differing_by_pass[pass]);
    std::printf("first-hit passes (AOVs): differ on %llu pixels away from edges and %llu on them (%s)\n",
                static_cast<unsigned long long>(m.aov_interior_differing), static_cast<unsigned long long>(m.aov_edge_differing),
                by_pass.c_str());
  }
  if (!diff.empty() && diff_is_pfm)
    std::printf("difference image: %s (|GPU - CPU| per channel, linear)\n", diff.string().c_str());
  else if (!diff.empty())
    std::printf("difference heatmap: %s (grey: same 8-bit sRGB values; dark purple = 1 step, pale yellow = %d steps)\n",
                diff.string().c_str(), max_steps);
  std::printf("tolerance (%s): %s\n", describe_tolerance(r.tolerance).c_str(), m.pass ? "PASS" : "FAIL");
}

int run_parity(const ParityArgs& args) {
  auto log = [&](const std::string& line) {
    if (!args.json) std::cerr << "vkray: " << line << "\n";
  };
  const LoadedScene loaded = load_scene_file(scene_file(args.scene), args.scene.environment);
  if (!args.diff.empty()) check_output_image(args.diff);
  RenderOptions options = render_options(&args.scene, &args.gpu, &args.cpu);
  log(describe(*loaded.scene, image_settings(*loaded.scene, options)));

  Session session(session_options(args.device));
  const std::string device = session.device_description();
  log("device " + device + (args.device.validate ? ", validation on" : ""));
  // One progress line per renderer, each from the moment that renderer starts.
  std::optional<Progress> progress;
  std::string stage;
  options.progress = [&](const char* unit, uint32_t done, uint32_t total) {
    if (stage != unit) {
      stage = unit;
      progress.reset();
      progress.emplace(!args.json, stage == "rows" ? "CPU reference" : "tracing");
    }
    progress->update(done, total, unit);
  };
  const ParityResult result = compare_with_reference(session, loaded.scene, options);
  session.close();

  int max_steps = 0;
  const bool diff_is_pfm = is_pfm(args.diff);
  if (!args.diff.empty()) max_steps = write_difference(result, args.diff);
  if (args.json) {
    nlohmann::json j = parity_json(result, loaded.scene->file.string(), device);
    if (!args.diff.empty()) {
      j["diff_image"] = args.diff.string();
      if (!diff_is_pfm) j["diff_max_steps"] = max_steps;
    }
    // Paths that are not UTF-8 print with U+FFFD rather than failing the report.
    std::cout << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  } else {
    print_text(result, device, args.diff, diff_is_pfm, max_steps);
  }
  return result.metrics.pass ? kExitOk : kExitParityFailed;
}

}  // namespace

Command add_parity_command(CLI::App& app) {
  auto args = std::make_shared<ParityArgs>();
  CLI::App* command = app.add_subcommand(
      "parity", "Render a scene on the GPU and with the CPU reference, compare, and exit 4 if they differ beyond the "
                "tolerance.");
  add_scene_flags(*command, args->scene);
  add_device_flags(*command, args->device);
  add_gpu_flags(*command, args->gpu);
  add_cpu_flags(*command, args->cpu, "CPU reference threads (default: one per hardware thread)");
  command->add_option("--diff", args->diff, "Write a heatmap of the per-pixel difference (.png or .pfm)");
  command->add_flag("--json", args->json, "Print the metrics as one JSON object on stdout (and nothing else)");
  command->footer(kExitCodes);
  return {command, [args] { return run_parity(*args); }};
}

}  // namespace vkray::cli
