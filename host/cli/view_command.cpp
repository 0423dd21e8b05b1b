// `vkray view`: the scene in a window, rendered progressively, moved with the keys and the mouse,
// reloaded in place (host/view/viewer.h).
#include <iostream>
#include <memory>

#include "base/errors.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "image/image_file.h"
#include "session/parts.h"
#ifdef VKRAY_HAVE_VIEWER
#include "view/viewer.h"
#endif

namespace vkray::cli {
namespace {

struct ViewArgs {
  SceneFlags scene;
  DeviceFlags device;
  GpuFlags gpu;
  DisplayFlags display;
  std::filesystem::path output;  // empty: <scene name>.png in the current folder
  ExrFlags exr;
  bool exit_when_done = false;
  std::filesystem::path frame_log;
};

int run_view(const ViewArgs& args) {
#ifdef VKRAY_HAVE_VIEWER
  view::ViewerOptions options;
  options.scene = scene_file(args.scene);
  options.environment = args.scene.environment;
  options.session = session_options(args.device);
  options.render = render_options(&args.scene, &args.gpu, nullptr);
  options.output = args.output.empty() ? std::filesystem::path(options.scene.stem().string() + ".png") : args.output;
  options.content = output_content(options.output, args.exr, args.display);
  // --tonemap and --exposure are the window's too: an EXR or PFM output is saved linear, not refused.
  OutputContent saved = options.content;
  if (image_file_type(options.output) != ImageFileType::png) saved.display = {};
  check_render_output(options.output, saved, false);
  options.exit_when_done = args.exit_when_done;
  options.frame_log = args.frame_log;
  return view::run_viewer(options);
#else
  static_cast<void>(args);
  throw UsageError("this vkray was built without its viewer: GLFW 3.3 and Dear ImGui were not found when it was built "
                   "(Debian: apt-get install libglfw3-dev libimgui-dev, then build again); `vkray render` and "
                   "`vkray watch` work without them");
#endif
}

}  // namespace

Command add_view_command(CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* command = app.add_subcommand(
      "view", "Show the scene in a window, rendered progressively: move the camera and the light with the keys and the "
              "mouse (F1 lists them), save with P; the scene and the shaders reload in place when they change.");
  add_scene_flags(*command, args->scene);
  command->add_option("-o,--output", args->output,
                      "What P saves: .png (as the window shows it), .pfm or .exr (linear radiance, with --aov's "
                      "passes); default: <scene name>.png in the current folder");
  add_exr_flags(*command, args->exr, "First-hit passes to accumulate and add to an .exr as layers");
  add_display_flags(*command, args->display);
  add_device_flags(*command, args->device);
  add_gpu_flags(*command, args->gpu);
  command->add_flag("--exit-when-done", args->exit_when_done,
                    "Once every pixel has its --spp samples, save the image to -o and exit");
  command->add_option("--frame-log", args->frame_log,
                      "Write a JSON line per frame: its time, samples, and how long the input or reload it shows waited");
  command->footer(kExitCodes);
  return {command, [args] { return run_view(*args); }, kExitOk, "closed"};
}

}  // namespace vkray::cli
