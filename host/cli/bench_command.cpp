// `vkray bench`: rays per second of the GPU path, the CPU reference and (when built with it) Intel
// Embree on the same scenes and the same rays, measured alternately in one run. A benchmark, not a
// test: it prints numbers and never fails on them.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <optional>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bvh/bvh.h"
#include "cli/commands.h"
#include "cpu/reference.h"
#include "base/errors.h"
#include "gpu/context.h"
#include "gpu/renderer.h"
#include "gpu/shader_compiler.h"
#include "session/paths.h"
#include "scene/scene.h"
#include "base/timing.h"
#ifdef VKRAY_HAVE_EMBREE
#include "embree/embree_tracer.h"
#endif

namespace vkray {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Rates {  // Mrays/s per repetition
  std::vector<double> gpu, cpu, embree;
};

struct SceneResult {
  std::string name;
  size_t triangles = 0;
  double load_ms = 0, bvh_ms = 0, embree_build_ms = 0;
  double gpu_frame_ms[2] = {0, 0};  // median trace time, primary / with shadows
  bool inline_scene = false;        // the GPU path ran the scene compiled into the shader, not the BVH
  Rates rates[2];                   // [0] camera rays only, [1] with shadow rays
};

std::string embree_name() {
#ifdef VKRAY_HAVE_EMBREE
  return std::string("Embree ") + bench::EmbreeTracer::version();
#else
  return "no Embree (not found at build time)";
#endif
}

std::string fixed(double value, int decimals) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

}  // namespace

int run_bench(const BenchCommand& cmd) {
  const std::filesystem::path scene_dir = default_scene().parent_path();
  const unsigned threads = cmd.threads ? cmd.threads : std::max(1u, std::thread::hardware_concurrency());
#ifdef VKRAY_HAVE_EMBREE
  const bool with_embree = cmd.embree;
#else
  const bool with_embree = false;
#endif

  gpu::ContextOptions options;
  options.device = cmd.device;
  gpu::Context ctx(options);
  const std::filesystem::path shader_dir = cmd.shader_dir.empty() ? default_shader_dir() : cmd.shader_dir;
  const gpu::TracePipeline pipeline(ctx, shader_dir, gpu::compile_compute_shader(shader_dir / "trace.comp", {shader_dir}));
  std::cerr << "vkray bench: device " << ctx.device_name() << " (" << ctx.driver_name() << "); CPU reference and "
            << (with_embree ? embree_name() : std::string("no Embree"))
            << " on " << threads << " threads; " << cmd.width << "x" << cmd.height << ", 1 sample per pixel, "
            << cmd.repeat << " rounds\n";

  std::vector<SceneResult> results;
  for (const std::string& name : cmd.scenes) {
    SceneResult r;
    r.name = name;
    auto start = Clock::now();
    const Scene scene = load_scene(scene_dir / (name + ".json"));
    r.load_ms = ms_since(start);
    r.triangles = scene.triangles.size();
    const Bvh bvh = build_bvh(primitive_boxes(scene));
    r.bvh_ms = bvh.build_seconds * 1e3;
    const gpu::GpuScene gpu_scene(ctx, scene, &bvh);
#ifdef VKRAY_HAVE_EMBREE
    std::optional<bench::EmbreeTracer> embree;
    if (with_embree) {
      embree.emplace(scene);
      r.embree_build_ms = embree->build_seconds() * 1e3;
    }
#endif
    const ImageSettings image{cmd.width, cmd.height, 1};
    // The path the measured renders take, decided once, so that the warm-up renders (lavapipe
    // compiles on the first dispatch) use the same two pipelines, with and without shadow rays.
    gpu::RenderOptions warm_up;
    r.inline_scene = gpu::use_inline_scene(gpu_scene, image, cmd.inline_scene);
    warm_up.inline_scene = r.inline_scene ? gpu::InlineScene::always : gpu::InlineScene::never;
    for (const bool shadows : {false, true}) {
      warm_up.shadows = shadows;
      gpu::render(ctx, pipeline, gpu_scene, {64, 64, 1}, warm_up);
    }
    std::vector<double> frame_ms[2];
    for (unsigned round = 0; round < cmd.repeat; ++round) {
      for (int mode = 0; mode < 2; ++mode) {
        const bool shadows = mode == 1;
        gpu::RenderOptions render_options = warm_up;
        render_options.shadows = shadows;
        gpu::RenderStats stats;
        gpu::render(ctx, pipeline, gpu_scene, image, render_options, &stats);
        r.rates[mode].gpu.push_back(double(stats.rays) / stats.trace_seconds * 1e-6);
        frame_ms[mode].push_back(stats.trace_seconds * 1e3);
#ifdef VKRAY_HAVE_EMBREE
        if (embree) {
          const auto e = embree->trace(cmd.width, cmd.height, shadows, threads);
          r.rates[mode].embree.push_back(double(e.rays) / e.seconds * 1e-6);
        }
#endif
        if (cmd.cpu_reference) {
          cpu::ReferenceOptions reference_options;
          reference_options.bvh = &bvh;
          reference_options.shadows = shadows;
          reference_options.threads = threads;
          const auto c = cpu::render_reference(scene, image, reference_options);
          r.rates[mode].cpu.push_back(double(c.rays) / c.seconds * 1e-6);
        }
      }
    }
    for (int mode = 0; mode < 2; ++mode) r.gpu_frame_ms[mode] = median(frame_ms[mode]);
    std::cerr << "vkray bench: " << name << " done\n";
    results.push_back(std::move(r));
  }

  if (cmd.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& r : results) {
      nlohmann::json j = {{"scene", r.name}, {"triangles", r.triangles}, {"width", cmd.width}, {"height", cmd.height},
                          {"bvh_build_ms", r.bvh_ms}, {"device", ctx.device_name()}, {"threads", threads},
                          {"gpu_path", r.inline_scene ? "inline" : "bvh"}};
      for (int mode = 0; mode < 2; ++mode) {
        const std::string key = mode == 0 ? "primary" : "primary_shadow";
        nlohmann::json m = {{"gpu_mrays", median(r.rates[mode].gpu)}, {"gpu_trace_ms", r.gpu_frame_ms[mode]}};
        if (cmd.cpu_reference) m["cpu_reference_mrays"] = median(r.rates[mode].cpu);
        if (with_embree) {
          m["embree_mrays"] = median(r.rates[mode].embree);
          m["gpu_over_embree"] = median(r.rates[mode].gpu) / median(r.rates[mode].embree);
        }
        j[key] = m;
      }
      if (with_embree) j["embree_build_ms"] = r.embree_build_ms;
      out.push_back(j);
    }
    std::cout << out.dump(2) << "\n";
    return kExitOk;
  }

  std::printf("%-13s %9s %9s %9s | %-44s | %-44s\n", "", "", "BVH build", "", "camera rays, Mrays/s", "camera + shadow rays, Mrays/s");
  std::printf("%-13s %9s %9s %9s | %8s %8s %8s %8s %8s | %8s %8s %8s %8s %8s\n", "scene", "triangles", "vkray ms", "Embree ms", "GPU",
              "GPU ms", "CPU ref", "Embree", "GPU/Emb", "GPU", "GPU ms", "CPU ref", "Embree", "GPU/Emb");
  for (const auto& r : results) {
    std::printf("%-13s %9zu %9s %9s", (r.name + (r.inline_scene ? " *" : "")).c_str(), r.triangles, fixed(r.bvh_ms, 1).c_str(),
                with_embree ? fixed(r.embree_build_ms, 1).c_str() : "-");
    for (int mode = 0; mode < 2; ++mode) {
      const double gpu = median(r.rates[mode].gpu), embree = median(r.rates[mode].embree);
      std::printf(" | %8s %8s %8s %8s %8s", fixed(gpu, 2).c_str(), fixed(r.gpu_frame_ms[mode], 0).c_str(),
                  cmd.cpu_reference ? fixed(median(r.rates[mode].cpu), 2).c_str() : "-",
                  with_embree ? fixed(embree, 2).c_str() : "-", with_embree ? fixed(gpu / embree, 2).c_str() : "-");
    }
    std::printf("\n");
  }
  if (std::any_of(results.begin(), results.end(), [](const SceneResult& r) { return r.inline_scene; }))
    std::printf("* GPU path: the scene compiled into the shader, no BVH (--inline-scene never to measure the BVH)\n");
  return kExitOk;
}

}  // namespace vkray
