// `vkray bench`: rays per second of the GPU path, the CPU reference and (when built with it) Intel
// Embree on the same scenes and the same rays, measured alternately in one run. A benchmark, not a
// test: it prints numbers and never fails on them.
#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <iostream>
#include <optional>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <unistd.h>

#include "base/errors.h"
#include "base/timing.h"
#include "bvh/bvh.h"
#include "image/image.h"
#include "image/image_file.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "load/scene_loader.h"
#include "scene/scene.h"
#include "session/cpu_render.h"
#include "session/paths.h"
#include "session/session.h"
#include "session/version.h"
#ifdef VKRAY_HAVE_EMBREE
#include "embree/embree_tracer.h"
#endif

namespace vkray::cli {
namespace {

// A benchmark's image is at least 8 pixels on a side (a workgroup); the rest as a render's.
constexpr ArgumentLimit kBenchWidthArgument{"width", 8, kMaxImageSide};
constexpr ArgumentLimit kBenchHeightArgument{"height", 8, kMaxImageSide};

struct BenchArgs {
  std::vector<std::string> scenes{"cornell", "bunny", "dragon", "dragon-field"};  // in scenes/
  uint32_t width = 1024, height = 1024;
  unsigned repeat = 3;
  DeviceFlags device;
  GpuFlags gpu;
  CpuFlags cpu;  // CPU reference and Embree threads; 0: one per hardware thread
  bool cpu_reference = true;
  bool embree = true;
  bool json = false;
};

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
  double bvh_sah_cost = 0;          // of vkray's tree (bvh/bvh.h)
  double upload_ms = 0;             // the scene packed for the GPU and copied to it, the BVH already built
  double gpu_frame_ms[2] = {0, 0};  // median trace time, primary / with shadows
  double readback_ms[2] = {0, 0};   // median
  double write_ms = 0;              // median: the camera-ray image written as PNG
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

int run_bench(const BenchArgs& args) {
  const std::filesystem::path scene_dir = default_scene().parent_path();
  RenderOptions measured = render_options(nullptr, &args.gpu, &args.cpu);
  measured.width = args.width;
  measured.height = args.height;
  measured.samples_per_pixel = 1;
  const unsigned threads = cpu_threads(measured);
#ifdef VKRAY_HAVE_EMBREE
  const bool with_embree = args.embree;
#else
  const bool with_embree = false;
#endif

  // Where the write stage's PNG goes for a moment: the system's temporary folder ($TMPDIR), a name
  // per process.
  std::error_code no_temp;
  const std::filesystem::path temp = std::filesystem::temp_directory_path(no_temp);
  if (no_temp)
    throw OutputError("no temporary folder for the write stage's PNG ($TMPDIR or /tmp): " + no_temp.message());
  const std::filesystem::path png = temp / ("vkray-bench-" + std::to_string(::getpid()) + ".png");
  Session session(session_options(args.device));
  std::cerr << "vkray bench: device " << session.device_description() << "; CPU reference and "
            << (with_embree ? embree_name() : std::string("no Embree")) << " on " << threads << " threads; "
            << args.width << "x" << args.height << ", 1 sample per pixel, " << args.repeat << " rounds\n";

  std::vector<SceneResult> results;
  for (const std::string& name : args.scenes) {
    SceneResult r;
    r.name = name;
    auto start = Clock::now();
    const auto scene = std::make_shared<const Scene>(load_scene(scene_dir / (name + ".json")));
    r.load_ms = ms_since(start);
    r.triangles = PrimitiveNumbering(*scene).sphere_first();  // as placed, instances counted each time
    // Both builds `repeat` times, alternately, each timed from the scene's triangles and with its
    // threads already started (Embree starts them in rtcNewDevice, before its timer): the medians.
    std::vector<double> bvh_ms, embree_build_ms;
    SceneBvh bvh;
#ifdef VKRAY_HAVE_EMBREE
    std::optional<bench::EmbreeTracer> embree;
#endif
    build_scene_bvh(*scene, threads);  // starts oneTBB's workers, untimed
    for (unsigned round = 0; round < args.repeat; ++round) {
      start = Clock::now();
      bvh = build_scene_bvh(*scene, threads);
      bvh_ms.push_back(ms_since(start));
#ifdef VKRAY_HAVE_EMBREE
      if (with_embree) {
        embree.reset();
        embree.emplace(*scene, threads);
        embree_build_ms.push_back(embree->build_seconds() * 1e3);
      }
#endif
    }
    r.bvh_ms = median(bvh_ms);
    r.embree_build_ms = median(embree_build_ms);
    r.bvh_sah_cost = sah_cost(bvh.primitives);
    const auto tree = std::make_shared<const SceneBvh>(std::move(bvh));
    const auto on_device = session.upload(scene, tree);
    r.upload_ms = (on_device.upload_seconds() - on_device.bvh_seconds()) * 1e3;
    // The path the measured renders take, decided once, so that the warm-up renders (lavapipe
    // compiles on the first dispatch) use the same two pipelines, with and without shadow rays.
    // `auto` is compiled in wherever the shader can hold the scene: a benchmark of rays per second
    // does not count the longer compile that `vkray render`'s auto weighs, and compiled in a small
    // scene's rays are faster (for a direct-model scene of 33 to 64 primitives, about as fast).
    RenderOptions choice = measured;
    if (choice.inline_scene == InlineScene::automatic) choice.inline_scene = InlineScene::always;
    r.inline_scene = session.compiles_scene_in(on_device, choice);
    RenderOptions options = measured;
    options.inline_scene = r.inline_scene ? InlineScene::always : InlineScene::never;
    RenderOptions warm_up = options;
    warm_up.width = warm_up.height = 64;
    for (const bool shadows : {false, true}) {
      warm_up.shadows = shadows;
      session.render(on_device, warm_up);
    }
    std::vector<double> frame_ms[2], readback_ms[2], write_ms;
    for (unsigned round = 0; round < args.repeat; ++round) {
      for (int mode = 0; mode < 2; ++mode) {
        options.shadows = mode == 1;
        const RenderResult rendered = session.render(on_device, options);
        const RenderStats& gpu = rendered.stats;
        r.rates[mode].gpu.push_back(double(gpu.rays) / gpu.trace_seconds * 1e-6);
        frame_ms[mode].push_back(gpu.trace_seconds * 1e3);
        readback_ms[mode].push_back(gpu.readback_seconds * 1e3);
        if (mode == 0) {
          start = Clock::now();
          write_image(rendered.image, png);
          write_ms.push_back(ms_since(start));
          std::filesystem::remove(png);
        }
#ifdef VKRAY_HAVE_EMBREE
        if (embree) {
          const auto e = embree->trace(args.width, args.height, options.shadows, threads);
          r.rates[mode].embree.push_back(double(e.rays) / e.seconds * 1e-6);
        }
#endif
        if (args.cpu_reference) {
          const RenderStats cpu = render_on_cpu(*scene, options, tree.get()).stats;
          r.rates[mode].cpu.push_back(double(cpu.rays) / cpu.trace_seconds * 1e-6);
        }
      }
    }
    for (int mode = 0; mode < 2; ++mode) {
      r.gpu_frame_ms[mode] = median(frame_ms[mode]);
      r.readback_ms[mode] = median(readback_ms[mode]);
    }
    r.write_ms = median(write_ms);
    std::cerr << "vkray bench: " << name << " done\n";
    results.push_back(std::move(r));
  }
  const std::string device = session.device_name();
  session.close();

  if (args.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& r : results) {
      nlohmann::json j = {{"scene", r.name}, {"triangles", r.triangles}, {"width", args.width}, {"height", args.height},
                          {"bvh_build_ms", r.bvh_ms}, {"device", device}, {"threads", threads},
                          {"gpu_path", r.inline_scene ? "inline" : "bvh"}, {"vkray_version", version_string()},
                          {"load_ms", r.load_ms}, {"bvh_sah_cost", r.bvh_sah_cost}, {"upload_ms", r.upload_ms},
                          {"write_png_ms", r.write_ms}};
      for (int mode = 0; mode < 2; ++mode) {
        const std::string key = mode == 0 ? "primary" : "primary_shadow";
        nlohmann::json m = {{"gpu_mrays", median(r.rates[mode].gpu)}, {"gpu_trace_ms", r.gpu_frame_ms[mode]},
                            {"readback_ms", r.readback_ms[mode]}};
        if (args.cpu_reference) m["cpu_reference_mrays"] = median(r.rates[mode].cpu);
        if (with_embree) {
          m["embree_mrays"] = median(r.rates[mode].embree);
          m["gpu_over_embree"] = median(r.rates[mode].gpu) / median(r.rates[mode].embree);
        }
        j[key] = m;
      }
      if (with_embree) j["embree_build_ms"] = r.embree_build_ms;
      out.push_back(j);
    }
    // Paths that are not UTF-8 print with U+FFFD rather than failing the report.
    std::cout << out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
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
                  args.cpu_reference ? fixed(median(r.rates[mode].cpu), 2).c_str() : "-",
                  with_embree ? fixed(embree, 2).c_str() : "-", with_embree ? fixed(gpu / embree, 2).c_str() : "-");
    }
    std::printf("\n");
  }
  if (std::any_of(results.begin(), results.end(), [](const SceneResult& r) { return r.inline_scene; }))
    std::printf("* GPU path: the scene compiled into the shader, no BVH (--inline-scene never to measure the BVH)\n");
  // Every stage of a render, as `vkray render` names them (medians; trace and read back with shadow
  // rays). The BVH build is part of a render's upload stage; here it is shown on its own.
  std::printf("\n%-13s %9s %9s %9s %9s %9s %9s %9s\n", "stages, ms", "load", "BVH build", "SAH cost", "upload", "trace",
              "read back", "write PNG");
  for (const auto& r : results)
    std::printf("%-13s %9s %9s %9s %9s %9s %9s %9s\n", r.name.c_str(), fixed(r.load_ms, 1).c_str(), fixed(r.bvh_ms, 1).c_str(),
                fixed(r.bvh_sah_cost, 1).c_str(), fixed(r.upload_ms, 1).c_str(), fixed(r.gpu_frame_ms[1], 1).c_str(),
                fixed(r.readback_ms[1], 1).c_str(), fixed(r.write_ms, 1).c_str());
  return kExitOk;
}

}  // namespace

Command add_bench_command(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* command = app.add_subcommand(
      "bench", "Measure rays per second of the GPU path, the CPU reference and Intel Embree (when built with it) on "
               "fixed scenes, alternately in one run. Prints a table (or --json); never fails on the numbers.");
  command->add_option("--scenes", args->scenes, "Scene names in scenes/ (default: cornell bunny dragon dragon-field)")
      ->delimiter(',');
  command->add_option("--width", args->width, "Image width")->check(within(kBenchWidthArgument));
  command->add_option("--height", args->height, "Image height")->check(within(kBenchHeightArgument));
  command->add_option("--repeat", args->repeat, "Rounds per scene; the median is reported")->check(CLI::Range(1, 100));
  add_cpu_flags(*command, args->cpu,
                "Threads for the CPU reference, Embree and both BVH builds (default: one per hardware thread)");
  add_device_flags(*command, args->device, /*validate=*/false);
  add_gpu_flags(*command, args->gpu);
  command->add_flag("!--no-cpu-reference", args->cpu_reference, "Leave the CPU reference out");
  command->add_flag("!--no-embree", args->embree, "Leave Embree out");
  command->add_flag("--json", args->json, "Print the results as JSON");
  command->footer(kExitCodes);
  return {command, [args] { return run_bench(*args); }};
}

}  // namespace vkray::cli
