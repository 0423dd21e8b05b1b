// `vkray watch`: render, then re-render whenever a shader, the scene or a file it uses changes,
// keeping the last good pipeline, scene and image through every mistake.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/errors.h"
#include "base/interrupt.h"
#include "base/timing.h"
#include "cli/commands.h"
#include "base/file_watcher.h"
#include "cli/flags.h"
#include "cli/report.h"
#include "image/image.h"
#include "image/image_file.h"
#include "session/failure.h"
#include "session/parts.h"
#include "session/paths.h"
#include "session/session.h"
#include "load/scene_loader.h"

namespace vkray::cli {
namespace {

struct WatchArgs {
  SceneFlags scene;
  DeviceFlags device;
  GpuFlags gpu;
  std::filesystem::path output;        // empty: <scene name>.png in the current folder
  std::optional<uint32_t> exit_after;  // stop after this many reloads (scripts and tests)
};

std::filesystem::path absolute_normal(const std::filesystem::path& p) { return std::filesystem::absolute(p).lexically_normal(); }

std::string names(const std::vector<std::filesystem::path>& files) {
  std::string text;
  for (const auto& f : files) text += (text.empty() ? "" : ", ") + printable(f.filename().string());
  return text;
}

// Prints what went wrong in a step of a reload: a shader error as its own `file:line: error:` lines,
// anything else as the command line reports it.
void report(const std::exception_ptr& error) {
  const Failure failure = describe_failure(error);
  if (failure.multiline)
    std::cerr << failure.message << "\n";
  else
    std::cerr << "vkray: " << failure.headline << ": " << failure.message << "\n";
}

class Watch {
 public:
  explicit Watch(const WatchArgs& args);
  int run();

 private:
  // Each step returns what the reload's line says of it; a failure is printed, and the last good
  // state stays.
  std::string reload_scene();
  std::string compile_shaders();
  std::string render(bool errors_reported);
  // Compiles the pipeline the scene needs (a small scene's own code, say), so that the time
  // reported for a render does not count it. Throws ShaderError.
  double prepare_pipeline();
  // Opens the device again after it was lost, with the last good shaders and scene.
  void reopen_device();
  bool is_scene_file(const std::filesystem::path& file) const;
  void watch_current_files();

  const WatchArgs& args_;
  const std::filesystem::path scene_file_;
  const std::filesystem::path environment_file_;  // --environment; empty: the scene's own
  const std::filesystem::path output_;
  SessionOptions session_options_;
  RenderOptions options_;
  std::unique_ptr<Session> session_;
  // The last good state; a failed reload leaves it as it was.
  std::shared_ptr<const Scene> scene_;
  std::optional<DeviceScene> on_device_;
  bool scene_broken_ = false, shader_broken_ = false;
  FileWatcher watcher_;
};

Watch::Watch(const WatchArgs& args)
    : args_(args),
      scene_file_(absolute_normal(scene_file(args.scene))),
      environment_file_(args.scene.environment.empty() ? std::filesystem::path() : absolute_normal(args.scene.environment)),
      output_(args.output.empty() ? std::filesystem::path(scene_file_.stem().string() + ".png") : args.output),
      session_options_(session_options(args.device)),
      options_(render_options(&args.scene, &args.gpu, nullptr)) {
  check_output_image(output_);  // before the device: a typo costs nothing
  session_options_.shader_dir = absolute_normal(session_options_.shader_dir.empty() ? default_shader_dir()
                                                                                   : session_options_.shader_dir);
  session_ = std::make_unique<Session>(session_options_);
  std::cerr << "vkray: device " << session_->device_description() << (args.device.validate ? ", validation on" : "")
            << "\n";
}

std::string Watch::reload_scene() {
  const auto start = Clock::now();
  try {
    auto loaded = std::make_shared<const Scene>(load_scene(scene_file_, nullptr, environment_file_));
    for (const auto& warning : loaded->warnings) std::cerr << "vkray: warning: " << warning << "\n";
    DeviceScene uploaded = session_->upload(loaded, nullptr);
    scene_ = std::move(loaded);
    on_device_ = std::move(uploaded);  // the old one goes whenever no render holds it any more
    scene_broken_ = false;
  } catch (const Cancelled&) {  // Ctrl-C: watching ends
    throw;
  } catch (const DeviceLostError&) {
    throw;
  } catch (const TimeoutError&) {  // a timed-out tile still runs: not the scene's fault
    report(std::current_exception());
    return "scene not uploaded while the device is busy";
  } catch (...) {  // the scene, a mesh, a limit, a scene too large for the device
    report(std::current_exception());
    scene_broken_ = true;
    return "scene has errors";
  }
  try {
    if (session_->has_shaders()) prepare_pipeline();
  } catch (const Cancelled&) {  // Ctrl-C: watching ends
    throw;
  } catch (const DeviceLostError&) {
    throw;
  } catch (...) {  // the shaders do not compile with the scene's generated code
    report(std::current_exception());
    shader_broken_ = true;
    return "scene " + format_ms(ms_since(start)) + ", shader has errors";
  }
  return "scene " + format_ms(ms_since(start));
}

std::string Watch::compile_shaders() {
  try {
    const Session::ShaderCompile compiled = session_->compile_shaders();
    shader_broken_ = false;
    // Also what the scene needs: its code compiled in, say, which follows the files as they are now.
    const double prepare_seconds = on_device_ ? prepare_pipeline() : 0.0;
    return "compile " + format_ms((compiled.seconds + prepare_seconds) * 1e3) +
           (compiled.spirv_changed ? "" : " (SPIR-V unchanged)");
  } catch (const Cancelled&) {  // Ctrl-C: watching ends
    throw;
  } catch (const DeviceLostError&) {
    throw;
  } catch (...) {  // a compile error, a binding declared otherwise, a validation message
    report(std::current_exception());
    shader_broken_ = true;
    return "shader has errors";
  }
}

double Watch::prepare_pipeline() { return session_->prepare(*on_device_, options_); }

std::string Watch::render(bool errors_reported) {
  if (scene_broken_ || shader_broken_ || !on_device_ || !session_->has_shaders()) {
    if (errors_reported) return "not rendered; " + output_.string() + " is unchanged";
    std::string broken = shader_broken_ || !session_->has_shaders() ? "shader" : "scene";
    if ((shader_broken_ || !session_->has_shaders()) && (scene_broken_ || !scene_)) broken = "shader and the scene";
    return "not rendered while the " + broken + " still has errors; " + output_.string() + " is unchanged";
  }
  const auto start = Clock::now();
  try {
    const RenderResult result = session_->render(*on_device_, options_);
    const double render_ms = ms_since(start);
    check_finite(result);  // an edited shader's NaN is reported, and the last good image kept
    write_image(result.image, output_);
    return "render " + format_ms(render_ms) + " -> " + output_.string();
  } catch (const Cancelled&) {
    throw;
  } catch (const DeviceLostError&) {
    throw;
  } catch (...) {  // a tile past its timeout (a shader that loops), a validation message, the output
    report(std::current_exception());
    return "render failed; " + output_.string() + " is unchanged";
  }
}

void Watch::reopen_device() {
  std::cerr << "vkray: the device was lost; opening it again\n";
  on_device_.reset();
  session_.reset();
  session_ = std::make_unique<Session>(session_options_);
  if (scene_) on_device_ = session_->upload(scene_, nullptr);
  if (!shader_broken_) session_->compile_shaders();
}

bool Watch::is_scene_file(const std::filesystem::path& file) const {
  if (file == scene_file_) return true;
  return scene_ && std::any_of(scene_->referenced_files.begin(), scene_->referenced_files.end(),
                               [&](const auto& r) { return absolute_normal(r) == file; });
}

void Watch::watch_current_files() {
  std::vector<std::filesystem::path> files = session_->shader_sources();
  files.push_back(scene_file_);
  if (scene_) files.insert(files.end(), scene_->referenced_files.begin(), scene_->referenced_files.end());
  watcher_.set_files(files);
}

int Watch::run() {
  // A new file that a shader will #include is seen too (the folder, not only today's files).
  watcher_.set_folder(session_options_.shader_dir, {".comp", ".glsl", ".h", ".inc"});
  try {
    const std::string scene_report = reload_scene();
    const std::string shader_report = compile_shaders();
    const std::string render_report = render(true);
    std::cerr << "vkray: initial: " << scene_report << ", " << shader_report << ", " << render_report << "\n";
    watch_current_files();
    std::cerr << "vkray: watching " << watcher_.file_count() << " files in " << watcher_.folder_count()
              << " folders; Ctrl-C to stop\n";

    for (uint32_t reload = 1; !args_.exit_after || reload <= *args_.exit_after; ++reload) {
      const std::vector<std::filesystem::path> changed = watcher_.wait(std::chrono::milliseconds(50), interrupt_fd());
      if (changed.empty()) break;  // SIGINT or SIGTERM
      const bool scene_changed = std::any_of(changed.begin(), changed.end(), [&](const auto& f) { return is_scene_file(f); });
      const bool shader_changed = std::any_of(changed.begin(), changed.end(), [&](const auto& f) { return !is_scene_file(f); });
      std::string line;
      for (int attempt = 0;; ++attempt) {
        try {
          line.clear();
          if (scene_changed) line += reload_scene() + ", ";
          if (shader_changed) line += compile_shaders() + ", ";
          const bool errors_reported = (scene_changed && scene_broken_) || (shader_changed && shader_broken_);
          line += render(errors_reported);
          break;
        } catch (const DeviceLostError&) {
          if (attempt > 0) throw;  // lost again at once: it cannot be brought back
          report(std::current_exception());
          reopen_device();
        }
      }
      std::cerr << "vkray: reload " << reload << " (" << names(changed) << " changed): " << line << "\n";
      try {
        watch_current_files();
      } catch (const Error&) {  // a folder past the inotify limit: watching goes on without it
        report(std::current_exception());
      }
    }
  } catch (const Cancelled&) {
    // Stopped mid-render: the image on disk is the last complete one.
  }
  // As for render: the device's teardown can raise validation messages (objects left alive), and
  // they must fail the command.
  on_device_.reset();
  session_->close();
  std::cerr << "vkray: stopped\n";
  return kExitOk;
}

}  // namespace

Command add_watch_command(CLI::App& app) {
  auto args = std::make_shared<WatchArgs>();
  CLI::App* command = app.add_subcommand(
      "watch", "Render, then re-render whenever the shaders, the scene or a file it uses changes. A broken shader or "
               "scene is reported as file:line and the last good image is kept. Ctrl-C stops it.");
  add_scene_flags(*command, args->scene);
  command->add_option("-o,--output", args->output, "Output image (default: <scene name>.png in the current folder)");
  add_device_flags(*command, args->device);
  add_gpu_flags(*command, args->gpu);
  command
      ->add_option("--exit-after", args->exit_after,
                   "Stop after N reloads (each change that was acted on counts, failed or not); for tests and scripts")
      ->check(CLI::Range(1, 1000000));
  command->footer(kExitCodes);
  return {command, [args] { return Watch(*args).run(); }, kExitOk, "stopped"};
}

}  // namespace vkray::cli
