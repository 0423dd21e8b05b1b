#include "compare/check.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "base/errors.h"
#include "base/interrupt.h"
#include "bvh/bvh.h"
#include "packing/inline_scene.h"
#include "session/cpu_render.h"
#include "session/session.h"
#include "load/scene_loader.h"

namespace vkray {

const char* path_name(InlineScene path) { return path == InlineScene::always ? "inline" : "bvh"; }

std::string case_name(const CheckCase& c) {
  return c.scene.stem().string() + "/" + path_name(c.path) + "/" + std::to_string(c.samples_per_pixel) + "spp";
}

std::vector<std::filesystem::path> check_scenes(const std::vector<std::filesystem::path>& folders) {
  std::vector<std::filesystem::path> result;
  for (const auto& folder : folders) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(folder))
      if (entry.path().extension() == ".json") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const auto& file : files)
      for (const auto& earlier : result)
        if (earlier.stem() == file.stem())
          throw InternalError("check cases " + earlier.string() + " and " + file.string() + " have one name");
    result.insert(result.end(), files.begin(), files.end());
  }
  return result;
}

std::string describe_plan(const CheckOptions& options) {
  std::string counts;
  for (const uint32_t spp : options.samples_per_pixel)
    counts += (counts.empty() ? "" : spp == options.samples_per_pixel.back() ? " and " : ", ") + std::to_string(spp);
  return std::to_string(options.scenes.size()) + " scenes at " + std::to_string(options.width) + "x" +
         std::to_string(options.height) + ", each on the BVH and, with " + std::to_string(gpu::kMaxInlinePrimitives) +
         " primitives or fewer, compiled into the shader; at " + counts + " spp";
}

void run_check(Session& session, const CheckOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); };
  for (const auto& file : options.scenes) {
    throw_if_interrupted();
    if (options.on_scene) options.on_scene(file);
    const auto scene = std::make_shared<const Scene>(load_scene(file));
    // One hierarchy, traversed by both renderers.
    const auto bvh = std::make_shared<const SceneBvh>(build_scene_bvh(*scene));
    const DeviceScene on_device = session.upload(scene, bvh);
    std::vector<InlineScene> paths{InlineScene::never};
    // (A scene with instances is never compiled in.)
    const size_t primitives = scene->instances.empty() ? scene->triangles.size() + scene->spheres.size() : 0;
    if (primitives > 0 && primitives <= gpu::kMaxInlinePrimitives) paths.push_back(InlineScene::always);
    for (const uint32_t spp : options.samples_per_pixel) {
      RenderOptions render = options.render;
      render.width = options.width;
      render.height = options.height;
      render.samples_per_pixel = spp;
      render.aovs = true;  // the first-hit passes are compared too
      if (options.on_case) options.on_case({file, paths.front(), spp});
      // The reference does not depend on the GPU path: rendered once for both.
      const auto cpu_start = Clock::now();
      std::vector<uint64_t> signatures;
      const RenderResult cpu = render_on_cpu(*scene, render, bvh.get(), &signatures);
      double shared_seconds = since(cpu_start);
      for (const InlineScene path : paths) {
        const CheckCase c{file, path, spp};
        if (options.on_case && path != paths.front()) options.on_case(c);
        const auto start = Clock::now();
        render.inline_scene = path;
        CheckResult result{c, scene->description, {}, 0};
        result.parity = judge_parity(image_settings(*scene, render), session.render(on_device, render), cpu, signatures,
                                     parity_tolerance(*scene), scene->extent());
        if (result.parity.gpu.stats.inline_scene != (path == InlineScene::always))
          throw InternalError(case_name(c) + ": the render did not take the path it was asked for");
        result.seconds = since(start) + shared_seconds;
        shared_seconds = 0;
        if (options.on_result) options.on_result(result);
      }
    }
  }
}

}  // namespace vkray
