// `vkray watch`: render, then re-render whenever a shader, the scene or a file it uses changes,
// keeping the last good pipeline, scene and image through every mistake.
#include <poll.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "base/errors.h"
#include "cli/file_watcher.h"
#include "gpu/context.h"
#include "gpu/renderer.h"
#include "gpu/shader_compiler.h"
#include "image/image.h"
#include "session/paths.h"
#include "scene/scene.h"
#include "cli/stop_signals.h"
#include "base/timing.h"

namespace vkray {
namespace {

std::string names(const std::vector<std::filesystem::path>& files) {
  std::string text;
  for (const auto& f : files) text += (text.empty() ? "" : ", ") + f.filename().string();
  return text;
}

int watch(const WatchCommand& cmd, const std::shared_ptr<gpu::ValidationLog>& validation_log) {
  const StopSignals stop;
  const std::filesystem::path scene_file =
      std::filesystem::absolute(cmd.flags.scene.empty() ? default_scene() : cmd.flags.scene).lexically_normal();
  const std::filesystem::path shader_dir =
      std::filesystem::absolute(cmd.flags.shader_dir.empty() ? default_shader_dir() : cmd.flags.shader_dir).lexically_normal();
  const std::filesystem::path output =
      cmd.output.empty() ? std::filesystem::path(scene_file.stem().string() + ".png") : cmd.output;
  check_output_path(output);

  gpu::ContextOptions options;
  options.validation = cmd.flags.validate;
  options.device = cmd.flags.device;
  options.validation_log = validation_log;
  gpu::Context ctx(options);
  std::cerr << "vkray: device " << ctx.device_name() << " (" << ctx.driver_name() << ")"
            << (cmd.flags.validate ? ", validation on" : "") << "\n";
  // Pipelines built from SPIR-V seen before in this session come from here instead of the driver's
  // compiler (Mesa also keeps its own on-disk shader cache across sessions).
  const vk::raii::PipelineCache pipeline_cache(ctx.device(), vk::PipelineCacheCreateInfo{});

  // The last good state. A failed reload leaves it untouched. The scene lives on the heap because
  // its GpuScene (BVH and buffers, rebuilt only when the scene changes) points at it.
  std::unique_ptr<Scene> scene;
  std::unique_ptr<gpu::GpuScene> gpu_scene;
  std::unique_ptr<gpu::TracePipeline> pipeline;
  std::vector<uint32_t> spirv;
  std::vector<std::filesystem::path> shader_sources{shader_dir / "trace.comp"};
  bool scene_broken = false, shader_broken = false;
  // Compiles the pipeline the current scene needs (a small scene's own code, say), so that the time
  // reported for a reload counts it. A ShaderError here is the shaders' (the generated code follows
  // the contract in inline_scene.glsl).
  auto prepare_pipeline = [&] {
    if (pipeline && gpu_scene)
      pipeline->pipeline(gpu::shader_variant(*gpu_scene, image_settings(*scene, cmd.flags), cmd.flags.inline_scene));
  };

  auto reload_scene = [&]() -> std::string {
    const auto start = Clock::now();
    try {
      auto loaded = std::make_unique<Scene>(load_scene(scene_file));
      for (const auto& warning : loaded->warnings) std::cerr << "vkray: warning: " << warning << "\n";
      auto uploaded = std::make_unique<gpu::GpuScene>(ctx, *loaded);
      ctx.queue().waitIdle();  // renders wait for their tiles; keep it so if that ever changes
      gpu_scene = std::move(uploaded);  // the old GpuScene goes first, while its scene still exists
      scene = std::move(loaded);
      scene_broken = false;
    } catch (const SceneError& e) {
      std::cerr << "vkray: error: " << e.what() << "\n";
      scene_broken = true;
      return "scene has errors";
    }
    try {
      prepare_pipeline();
    } catch (const ShaderError& e) {
      std::cerr << e.what() << "\n";
      shader_broken = true;
      return "scene " + format_ms(ms_since(start)) + ", shader has errors";
    }
    return "scene " + format_ms(ms_since(start));
  };
  auto recompile = [&]() -> std::string {
    const auto start = Clock::now();
    try {
      gpu::CompiledShader compiled = gpu::compile_compute_shader(shader_dir / "trace.comp", {shader_dir});
      shader_sources = compiled.sources;
      shader_broken = false;
      // The SPIR-V without a scene compiled in says nothing about the one with it (its functions are
      // not in the other), so a scene that is compiled in is always recompiled.
      const bool compiled_in = gpu_scene && gpu::use_inline_scene(*gpu_scene, image_settings(*scene, cmd.flags),
                                                                  cmd.flags.inline_scene);
      if (pipeline && compiled.spirv == spirv && !compiled_in)
        return "compile " + format_ms(ms_since(start)) + " (SPIR-V unchanged)";
      // Renders wait for their last tile, so no work uses the old pipeline now; wait anyway, so
      // that stays true if rendering ever overlaps with reloading.
      ctx.queue().waitIdle();
      pipeline = std::make_unique<gpu::TracePipeline>(ctx, shader_dir, compiled, &pipeline_cache);
      prepare_pipeline();
      spirv = std::move(compiled.spirv);
      ctx.check_validation("pipeline creation");
      return "compile " + format_ms(ms_since(start));
    } catch (const ShaderError& e) {
      std::cerr << e.what() << "\n";
      shader_broken = true;
      return "shader has errors";
    }
  };
  // Renders with the last good state and replaces the image; returns what to report.
  // `errors_reported` says whether this reload's report already named what is broken.
  auto render = [&](bool errors_reported) -> std::string {
    if (scene_broken || shader_broken || !gpu_scene || !pipeline) {
      if (errors_reported) return "not rendered; " + output.string() + " is unchanged";
      std::string broken = shader_broken || !pipeline ? "shader" : "scene";
      if ((shader_broken || !pipeline) && (scene_broken || !scene)) broken = "shader and the scene";
      return "not rendered while the " + broken + " still has errors; " + output.string() + " is unchanged";
    }
    const ImageSettings image = image_settings(*scene, cmd.flags);
    gpu::RenderOptions render_options;
    render_options.cancel = [&] { return stop.pending(); };
    render_options.inline_scene = cmd.flags.inline_scene;
    const auto start = Clock::now();
    const Image result = gpu::render(ctx, *pipeline, *gpu_scene, image, render_options);
    const double render_ms = ms_since(start);
    ctx.check_validation("render");
    write_image(result, output);
    return "render " + format_ms(render_ms) + " -> " + output.string();
  };

  FileWatcher watcher;
  // The scene and the files it references count as "the scene"; everything else is a shader.
  auto is_scene_file = [&](const std::filesystem::path& f) {
    if (f == scene_file) return true;
    return scene && std::any_of(scene->referenced_files.begin(), scene->referenced_files.end(), [&](const auto& r) {
             return std::filesystem::absolute(r).lexically_normal() == f;
           });
  };
  auto watch_current_files = [&] {
    std::vector<std::filesystem::path> files = shader_sources;
    files.push_back(scene_file);
    if (scene) files.insert(files.end(), scene->referenced_files.begin(), scene->referenced_files.end());
    watcher.set_files(files);
  };
  watcher.set_folder(shader_dir, {".comp", ".glsl", ".h", ".inc"});

  try {
    const std::string scene_report = reload_scene();
    const std::string shader_report = recompile();
    std::cerr << "vkray: initial: " << scene_report << ", " << shader_report << ", " << render(true) << "\n";
    watch_current_files();
    std::cerr << "vkray: watching " << watcher.file_count() << " files in " << watcher.folder_count()
              << " folders; Ctrl-C to stop\n";

    for (uint32_t reload = 1; !cmd.exit_after || reload <= *cmd.exit_after; ++reload) {
      const std::vector<std::filesystem::path> changed = watcher.wait(std::chrono::milliseconds(50), stop.fd());
      if (changed.empty()) break;  // SIGINT or SIGTERM
      const bool scene_changed = std::any_of(changed.begin(), changed.end(), is_scene_file);
      const bool shader_changed = std::any_of(changed.begin(), changed.end(), [&](const auto& f) { return !is_scene_file(f); });
      std::string report;
      if (scene_changed) report += reload_scene() + ", ";
      if (shader_changed) report += recompile() + ", ";
      const bool errors_reported = (scene_changed && scene_broken) || (shader_changed && shader_broken);
      std::cerr << "vkray: reload " << reload << " (" << names(changed) << " changed): " << report
                << render(errors_reported) << "\n";
      watch_current_files();
    }
  } catch (const Cancelled&) {
    // Stopped mid-render: the image on disk is the last complete one.
  }
  ctx.queue().waitIdle();
  return kExitOk;
}

}  // namespace

int run_watch(const WatchCommand& cmd) {
  // As for render: the device's teardown can raise validation messages (leaked objects), and they
  // must fail the command.
  auto validation_log = std::make_shared<gpu::ValidationLog>();
  const int code = watch(cmd, validation_log);
  if (validation_log->count() > 0)
    throw DeviceError(std::to_string(validation_log->count()) + " validation message(s); the first:\n  " +
                      validation_log->messages().front());
  std::cerr << "vkray: stopped\n";
  return code;
}

}  // namespace vkray
