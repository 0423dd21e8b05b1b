// vkray's command line: parses arguments, runs a subcommand, and turns any error into one message on
// stderr and the documented exit code (session/failure.h).
#include <iostream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>
#include "cli/commands.h"
#include "base/errors.h"
#include "session/failure.h"

namespace {

constexpr const char* kExitCodes =
    "Exit codes:\n"
    "  0  success\n"
    "  1  bad input: scene, mesh or shader file, an output file that cannot be written, or an input past a\n"
    "     limit (primitives, sizes, host memory, inotify watches)\n"
    "  2  usage: unknown command or option, bad option value\n"
    "  3  Vulkan or device failure (no device, failed call, timeout, validation message)\n"
    "  4  parity: the GPU and CPU images differ beyond the documented tolerance\n"
    "  70  internal error: a bug in vkray (please report it)\n"
    "  130  interrupted by SIGINT (Ctrl-C) or SIGTERM; nothing was written\n";

// --inline-scene: how a scene is traced (host/packing/inline_scene.h).
CLI::Option* add_inline_scene_option(CLI::App* cmd, vkray::gpu::InlineScene& value) {
  using vkray::gpu::InlineScene;
  static const std::map<std::string, InlineScene> names{
      {"auto", InlineScene::automatic}, {"always", InlineScene::always}, {"never", InlineScene::never}};
  return cmd
      ->add_option_function<std::string>(
          "--inline-scene", [&value](const std::string& name) { value = names.at(name); },
          "GPU path for scenes of at most 32 primitives: compile the scene into the shader (every primitive "
          "tested, no BVH) 'always', 'never', or 'auto' (default: when the render has at least 2^20 camera "
          "rays, so that the longer compile pays off)")
      ->option_text("auto|always|never")
      ->check(CLI::IsMember({"auto", "always", "never"}));
}

// Flags every rendering command takes.
void add_render_flags(CLI::App* cmd, vkray::RenderFlags& flags) {
  cmd->add_option("scene", flags.scene, "Scene file (default: the Cornell box, scenes/cornell.json)");
  cmd->add_option("--width", flags.width, "Image width in pixels (overrides the scene)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", flags.height, "Image height in pixels (overrides the scene)")->check(CLI::Range(1, 16384));
  cmd->add_option("--spp", flags.spp, "Samples per pixel (overrides the scene)")->check(CLI::Range(1, 65536));
  cmd->add_option("--device", flags.device, "Vulkan device: index or part of its name (see `vkray devices`)");
  cmd->add_option("--shader-dir", flags.shader_dir, "Folder with trace.comp and its includes");
  cmd->add_flag("--validate", flags.validate, "Enable the Khronos validation layer; any message is an error");
  cmd->add_option("--threads", flags.threads, "CPU reference threads (default: one per hardware thread)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--tile-timeout", flags.tile_timeout_ms,
                  "Longest one GPU submission (a tile) may run, in milliseconds, before the render fails with exit 3 "
                  "(default 60000)")
      ->check(CLI::Range(1, 3600000));
  add_inline_scene_option(cmd, flags.inline_scene);
  cmd->footer(kExitCodes);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace vkray;
  CLI::App app("vkray: a raytracer on Vulkan compute shaders, with a headless renderer for any Vulkan device "
               "(lavapipe included).");
  app.footer(kExitCodes);
  app.require_subcommand(1);

  RenderCommand render;
  auto* render_cmd = app.add_subcommand("render", "Render a scene to a PNG or PFM image.");
  add_render_flags(render_cmd, render.flags);
  render_cmd->add_option("-o,--output", render.output, "Output image, .png (8-bit sRGB) or .pfm (float, linear); "
                                                       "default: <scene name>.png in the current folder");
  render_cmd->add_option("--renderer", render.renderer, "gpu (Vulkan compute shader) or cpu (the CPU reference)")
      ->check(CLI::IsMember({"gpu", "cpu"}));
  render_cmd->add_flag("-q,--quiet", render.quiet, "Print only warnings and errors");

  ParityCommand parity;
  auto* parity_cmd = app.add_subcommand(
      "parity", "Render a scene on the GPU and with the CPU reference, compare, and exit 4 if they differ "
                "beyond the tolerance.");
  add_render_flags(parity_cmd, parity.flags);
  parity_cmd->add_option("--diff", parity.diff, "Write a heatmap of the per-pixel difference (.png or .pfm)");
  parity_cmd->add_flag("--json", parity.json, "Print the metrics as one JSON object on stdout (and nothing else)");

  WatchCommand watch;
  auto* watch_cmd = app.add_subcommand(
      "watch", "Render, then re-render whenever the shaders, the scene or a file it uses changes. A broken "
               "shader or scene is reported as file:line and the last good image is kept. Ctrl-C stops it.");
  add_render_flags(watch_cmd, watch.flags);
  watch_cmd->add_option("-o,--output", watch.output, "Output image (default: <scene name>.png in the current folder)");
  watch_cmd->add_option("--exit-after", watch.exit_after,
                        "Stop after N reloads (each change that was acted on counts, failed or not); for tests and scripts")
      ->check(CLI::Range(1, 1000000));

  BenchCommand bench;
  auto* bench_cmd = app.add_subcommand(
      "bench", "Measure rays per second of the GPU path, the CPU reference and Intel Embree (when built with it) on "
               "fixed scenes, alternately in one run. Prints a table (or --json); never fails on the numbers.");
  bench_cmd->add_option("--scenes", bench.scenes, "Scene names in scenes/ (default: cornell bunny dragon dragon-field)")
      ->delimiter(',');
  bench_cmd->add_option("--width", bench.width, "Image width")->check(CLI::Range(8, 16384));
  bench_cmd->add_option("--height", bench.height, "Image height")->check(CLI::Range(8, 16384));
  bench_cmd->add_option("--repeat", bench.repeat, "Rounds per scene; the median is reported")->check(CLI::Range(1, 100));
  bench_cmd->add_option("--threads", bench.threads, "Threads for the CPU reference and Embree")->check(CLI::Range(1, 256));
  bench_cmd->add_option("--device", bench.device, "Vulkan device: index or part of its name");
  bench_cmd->add_option("--shader-dir", bench.shader_dir, "Folder with trace.comp and its includes (to measure a variant)");
  add_inline_scene_option(bench_cmd, bench.inline_scene);
  bench_cmd->add_flag("!--no-cpu-reference", bench.cpu_reference, "Leave the CPU reference out");
  bench_cmd->add_flag("!--no-embree", bench.embree, "Leave Embree out");
  bench_cmd->add_flag("--json", bench.json, "Print the results as JSON");

  auto* devices_cmd = app.add_subcommand("devices", "List Vulkan devices with the properties that matter to vkray.");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }

  try {
    if (*render_cmd) return run_render(render);
    if (*parity_cmd) return run_parity(parity);
    if (*watch_cmd) return run_watch(watch);
    if (*bench_cmd) return run_bench(bench);
    if (*devices_cmd) return run_devices();
  } catch (...) {
    const Failure failure = describe_failure(std::current_exception());
    std::cerr << "vkray: " << failure.headline << (failure.multiline ? ":\n" : ": ") << failure.message << "\n";
    return failure.exit_code;
  }
  return kExitUsage;
}
