// `vkray render`: one scene to one image, on the GPU or with the CPU reference.
#include <iostream>
#include <memory>
#include <string>

#include "base/errors.h"
#include "base/timing.h"
#include "bvh/bvh.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "cli/report.h"
#include "image/aovs.h"
#include "image/exr.h"
#include "image/image.h"
#include "image/image_file.h"
#include "session/cpu_render.h"
#include "session/parts.h"
#include "session/session.h"
#include "load/scene_loader.h"

namespace vkray::cli {
namespace {

struct RenderArgs {
  SceneFlags scene;
  DeviceFlags device;
  GpuFlags gpu;
  CpuFlags cpu;
  DisplayFlags display;
  std::filesystem::path output;  // empty: <scene name>.png in the current folder
  std::string renderer = "gpu";  // "gpu" or "cpu"
  ExrFlags exr;
  bool quiet = false;
};

int run_render(const RenderArgs& args) {
  const auto total_start = Clock::now();
  auto log = [&](const std::string& line) {
    if (!args.quiet) std::cerr << "vkray: " << line << "\n";
  };
  const LoadedScene loaded = load_scene_file(scene_file(args.scene), args.scene.environment);
  const std::filesystem::path output =
      args.output.empty() ? std::filesystem::path(loaded.scene->name + ".png") : args.output;
  const OutputContent content = output_content(output, args.exr, args.display);
  check_render_output(output, content, args.scene.region.has_value());
  RenderOptions options = render_options(&args.scene, &args.gpu, &args.cpu);
  options.aovs = !content.passes.empty();
  const ImageSettings image = image_settings(*loaded.scene, options);

  RenderResult result;
  std::string phases, device = kCpuReferenceDevice;
  if (args.renderer == "cpu") {
    log("renderer CPU reference, " + std::to_string(cpu_threads(options)) + " threads");
    log(describe(*loaded.scene, image));
    Progress progress(!args.quiet, "CPU reference");
    options.progress = [&](const char* unit, uint32_t done, uint32_t total) { progress.update(done, total, unit); };
    result = render_on_cpu(*loaded.scene, options);
    phases = "load " + format_ms(loaded.load_ms) + " | trace " + format_ms(result.stats.trace_seconds * 1e3);
  } else {
    log(describe(*loaded.scene, image));
    // The BVH is built while the device opens and the shaders compile, which need one thread.
    BackgroundBvh bvh(loaded.scene);
    Session session(session_options(args.device));
    device = session.device_description();
    log("device " + device + (args.device.validate ? ", validation on" : ""));
    double compile_seconds = session.compile_shaders().seconds, upload_seconds = 0;
    {
      const auto on_device = session.upload(loaded.scene, std::make_shared<const SceneBvh>(bvh.get()));
      upload_seconds = on_device.upload_seconds();
      if (const auto& e = loaded.scene->environment)
        log("environment " + e->file.string() + ", " + std::to_string(e->radiance->width) + " x " + std::to_string(e->radiance->height) +
            " texels: distribution built in " + format_ms(on_device.environment_seconds() * 1e3));
      // The scene's pipeline compiled now, so that the compile phase counts it (a small scene's own
      // code is compiled only now that the scene is packed).
      compile_seconds += session.prepare(on_device, options);
      Progress progress(!args.quiet, "tracing");
      options.progress = [&](const char* unit, uint32_t done, uint32_t total) { progress.update(done, total, unit); };
      result = session.render(on_device, options);
    }
    // The device goes before anything is written: its teardown can raise validation messages
    // (objects left alive), and they must fail the command.
    session.close();
    const RenderStats& s = result.stats;
    phases = "load " + format_ms(loaded.load_ms) + " | compile " + format_ms(compile_seconds * 1e3) + " | upload " +
             format_ms((upload_seconds + s.upload_seconds) * 1e3) + " | trace " + format_ms(s.trace_seconds * 1e3) + " (" +
             std::to_string(s.tiles) + (s.tiles == 1 ? " tile" : " tiles") +
             (s.inline_scene ? ", scene compiled into the shader" : "") + ") | read back " +
             format_ms(s.readback_seconds * 1e3);
  }

  const auto start = Clock::now();
  if (is_part(result)) log("pixels " + to_string(result.region) + " of " + std::to_string(image.width) + " x " +
                           std::to_string(image.height) + ": a part for `vkray merge`");
  write_render(output, *loaded.scene, result, content, device);
  log(phases + " | write " + format_ms(ms_since(start)));
  log(std::to_string(result.stats.rays) + " rays (camera + shadow), " +
      format_rate(result.stats.rays, result.stats.trace_seconds) + "; total " + format_ms(ms_since(total_start)));
  log("wrote " + output.string());
  return kExitOk;
}

}  // namespace

Command add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* command = app.add_subcommand("render", "Render a scene to a PNG, PFM or OpenEXR image.");
  add_scene_flags(*command, args->scene);
  add_region_flag(*command, args->scene);
  command->add_option("-o,--output", args->output, "Output image, .png (8-bit sRGB), .pfm (float, linear) or .exr "
                                                   "(half float, linear); default: <scene name>.png in the current folder");
  add_exr_flags(*command, args->exr, "First-hit passes to add to an .exr as layers");
  add_display_flags(*command, args->display);
  add_device_flags(*command, args->device);
  add_gpu_flags(*command, args->gpu);
  command->add_option("--renderer", args->renderer, "gpu (Vulkan compute shader) or cpu (the CPU reference)")
      ->check(CLI::IsMember({"gpu", "cpu"}));
  add_cpu_flags(*command, args->cpu, "CPU reference threads (default: one per hardware thread)");
  command->add_flag("-q,--quiet", args->quiet, "Print only warnings and errors");
  command->footer(kExitCodes);
  return {command, [args] { return run_render(*args); }};
}

}  // namespace vkray::cli
