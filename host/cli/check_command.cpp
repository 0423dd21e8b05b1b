// `vkray check`: the parity suite (compare/check.h) on the chosen device, reported for a person (one
// line per case, the command that reproduces each failure), for CI (JUnit XML) and for scripts (JSON).
// What a driver developer pastes into a bug report: the header names vkray, the device and driver.
#include <algorithm>
#include <cstdlib>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/errors.h"
#include "cli/commands.h"
#include "cli/flags.h"
#include "compare/junit.h"
#include "compare/parity_report.h"
#include "cli/report.h"
#include "image/image_file.h"
#include "compare/check.h"
#include "session/paths.h"
#include "session/session.h"
#include "session/version.h"

namespace vkray::cli {
namespace {

// The tolerance of renders that make random decisions (compare/parity.h).
ParityTolerance stochastic_tolerance() {
  ParityTolerance t;
  t.stochastic = true;
  return t;
}

struct CheckArgs {
  DeviceFlags device;
  GpuFlags gpu;
  CpuFlags cpu;
  std::optional<uint32_t> width, height;
  std::vector<std::string> cases;  // scene names (file stems); empty: all
  std::filesystem::path junit;
  std::filesystem::path failures = "vkray-check-failures";
  bool json = false;
};

// A word for a shell: as it is when it is plain, else in single quotes.
std::string shell_word(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-./=:,+@%") ==
                           std::string::npos)
    return word;
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// The Vulkan loader's variables that choose drivers, devices and layers, as they are set: what a
// driver developer uses to test their own build, so a reproduce command carries them.
std::string loader_environment() {
  std::string words;
  for (const char* name : {"VK_DRIVER_FILES", "VK_ICD_FILENAMES", "VK_ADD_DRIVER_FILES", "VK_LOADER_DRIVERS_SELECT",
                           "VK_LOADER_DRIVERS_DISABLE", "VK_LAYER_PATH", "VK_ADD_LAYER_PATH"})
    if (const char* value = std::getenv(name)) words += std::string(name) + "=" + shell_word(value) + " ";
  return words;
}

// The one command that renders `c` again as the check did, in a process of its own, and prints its
// metrics: this vkray, on this device, with the loader's environment of this run.
std::string reproduce_command(const CheckCase& c, const CheckArgs& args, const CheckOptions& options,
                              const DeviceInfo& device) {
  const auto exe = executable_path();
  std::string command = loader_environment() + shell_word(exe.empty() ? "vkray" : exe.string()) + " parity " +
                        shell_word(std::filesystem::absolute(c.scene).lexically_normal().string()) + " --width " +
                        std::to_string(options.width) + " --height " + std::to_string(options.height) + " --spp " +
                        std::to_string(c.samples_per_pixel) + " --inline-scene " +
                        (c.path == InlineScene::always ? "always" : "never") + " --device " +
                        std::to_string(device.index);
  if (!args.device.shader_dir.empty())
    command += " --shader-dir " + shell_word(std::filesystem::absolute(args.device.shader_dir).string());
  if (args.device.validate) command += " --validate";
  if (args.gpu.tile_timeout_ms != GpuFlags{}.tile_timeout_ms)
    command += " --tile-timeout " + std::to_string(args.gpu.tile_timeout_ms);
  return command;
}

std::string file_name(const CheckCase& c) {
  return c.scene.stem().string() + "-" + path_name(c.path) + "-" + std::to_string(c.samples_per_pixel) + "spp.png";
}

std::string now_iso8601() {
  const std::time_t now = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", std::gmtime(&now));
  return text;
}

// What a person reads of one case.
struct Outcome {
  CheckCase c;
  bool pass = true;
  std::string summary;  // the metrics in one line
  double seconds = 0;
  std::string description;
  std::string command;            // reproduces it
  std::filesystem::path heatmap;  // when it failed
  nlohmann::json metrics;
};

class CheckReport {
 public:
  CheckReport(const CheckArgs& args, const CheckOptions& options) : args_(args), options_(options) {}

  // The device, once it is open: the header names it.
  void opened(const DeviceInfo& device) {
    device_ = device;
    if (args_.json) return;
    std::printf("vkray check: vkray %s\n", version_string());
    std::printf("device %u: %s (%s), driver %s, Vulkan %s\n", device_.index, device_.name.c_str(), device_.type.c_str(),
                device_.driver.c_str(), device_.api_version.c_str());
    if (!loader_environment().empty()) std::printf("loader: %s\n", loader_environment().c_str());
    std::printf("%s; tolerance: %s; for scenes with random decisions (paths, area lights, glass, a lens): %s\n",
                describe_plan(options_).c_str(), describe_tolerance({}).c_str(), describe_tolerance(stochastic_tolerance()).c_str());
    std::fflush(stdout);
  }

  void running(const CheckCase& c) { running_ = c; }

  void add(const CheckResult& r) {
    Outcome o;
    o.c = r.c;
    o.pass = r.parity.metrics.pass;
    o.summary = describe_metrics(r.parity.metrics);
    o.seconds = r.seconds;
    o.description = r.description;
    o.command = reproduce_command(r.c, args_, options_, device_);
    o.metrics = parity_json(r.parity, r.c.scene.string(), device_.name);
    if (!o.pass) {
      std::error_code ec;
      std::filesystem::create_directories(args_.failures, ec);
      if (ec) throw OutputError(args_.failures.string() + ": cannot create folder: " + ec.message());
      o.heatmap = args_.failures / file_name(r.c);
      o.metrics["diff_max_steps"] = write_difference(r.parity, o.heatmap);
    }
    if (!args_.json) {
      std::printf("%s  %-40s %s (%.2f s)\n", o.pass ? "pass" : "FAIL", case_name(o.c).c_str(), o.summary.c_str(),
                  o.seconds);
      if (!o.pass && !o.description.empty()) std::printf("      case: %s\n", o.description.c_str());
      if (!o.pass) std::printf("      heatmap: %s\n      reproduce: %s\n", o.heatmap.c_str(), o.command.c_str());
      std::fflush(stdout);
    }
    outcomes_.push_back(std::move(o));
  }

  // The case that could not run (or the scene that could not load, or the device that could not
  // open), and why.
  void error(const std::string& message) { error_ = message; }

  size_t failed() const {
    return size_t(std::count_if(outcomes_.begin(), outcomes_.end(), [](const Outcome& o) { return !o.pass; }));
  }

  void finish() const {
    if (!args_.junit.empty()) write_file_atomically(args_.junit, junit_xml(junit()));
    if (args_.json) {
      std::cout << json().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    } else if (!error_) {
      std::printf("vkray check: %zu of %zu cases pass", outcomes_.size() - failed(), outcomes_.size());
      if (failed()) std::printf("; %zu fail (heatmaps in %s)", failed(), args_.failures.c_str());
      std::printf("\n");
    }
  }

 private:
  std::vector<std::pair<std::string, std::string>> properties() const {
    return {{"vkray_version", version_string()},
            {"device_index", std::to_string(device_.index)},
            {"device", device_.name},
            {"device_type", device_.type},
            {"driver", device_.driver},
            {"vulkan_version", device_.api_version},
            {"loader_environment", loader_environment()},
            {"image", std::to_string(options_.width) + "x" + std::to_string(options_.height)},
            {"tolerance", describe_tolerance({})},
            {"tolerance_stochastic", describe_tolerance(stochastic_tolerance())}};
  }

  // JUnit's names of a case (or, before any case ran, of the device).
  std::pair<std::string, std::string> junit_names(const std::optional<CheckCase>& c) const {
    if (!c) return {"vkray.check", "device"};
    return {"vkray.check." + c->scene.stem().string(),
            std::string(path_name(c->path)) + "_" + std::to_string(c->samples_per_pixel) + "spp"};
  }

  JunitSuite junit() const {
    JunitSuite suite{"vkray check", timestamp_, properties(), {}};
    for (const auto& o : outcomes_) {
      JunitCase c;
      std::tie(c.classname, c.name) = junit_names(o.c);
      c.seconds = o.seconds;
      c.output = o.summary + "\n" + (o.description.empty() ? "" : o.description + "\n") + "reproduce: " + o.command;
      if (!o.pass)
        c.failure = JunitCase::Problem{"parity tolerance does not hold: " + o.summary,
                                       "heatmap: " + o.heatmap.string() + "\nreproduce: " + o.command};
      suite.cases.push_back(std::move(c));
    }
    if (error_) {
      JunitCase c;
      std::tie(c.classname, c.name) = junit_names(running_);
      c.error = JunitCase::Problem{*error_, *error_};
      suite.cases.push_back(std::move(c));
    }
    return suite;
  }

  nlohmann::json json() const {
    nlohmann::json cases = nlohmann::json::array();
    for (const auto& o : outcomes_) {
      nlohmann::json c = {{"name", case_name(o.c)},         {"scene", o.c.scene.string()},
                          {"path", path_name(o.c.path)},     {"samples_per_pixel", o.c.samples_per_pixel},
                          {"pass", o.pass},                  {"seconds", o.seconds},
                          {"description", o.description},    {"command", o.command},
                          {"metrics", o.metrics}};
      if (!o.pass) c["heatmap"] = o.heatmap.string();
      cases.push_back(std::move(c));
    }
    nlohmann::json j;
    for (const auto& [key, value] : properties()) j[key] = value;
    j["cases"] = std::move(cases);
    j["passed"] = outcomes_.size() - failed();
    j["failed"] = failed();
    if (error_) j["error"] = {{"case", running_ ? case_name(*running_) : "device"}, {"message", *error_}};
    return j;
  }

  const CheckArgs& args_;
  const CheckOptions& options_;
  const std::string timestamp_ = now_iso8601();  // when the check started
  DeviceInfo device_{};  // a copy: the session closes before the report is finished
  std::vector<Outcome> outcomes_;
  std::optional<CheckCase> running_;
  std::optional<std::string> error_;
};

// The scenes the check runs: every shipped scene and every adversarial case, or those --case names.
std::vector<std::filesystem::path> chosen_scenes(const std::vector<std::string>& names) {
  const auto all = check_scenes({default_scene_dir(), default_check_dir()});
  if (names.empty()) return all;
  std::vector<std::filesystem::path> chosen;
  for (const auto& name : names) {
    const auto found = std::find_if(all.begin(), all.end(), [&](const auto& f) { return f.stem().string() == name; });
    if (found == all.end()) {
      std::string known;
      for (const auto& f : all) known += (known.empty() ? "" : ", ") + f.stem().string();
      throw UsageError("--case " + printable(name) + ": no such case; the cases are " + known);
    }
    if (std::find(chosen.begin(), chosen.end(), *found) == chosen.end()) chosen.push_back(*found);
  }
  return chosen;
}

// Throws OutputError unless `folder` is a folder or can be made one (its parent exists).
void check_failures_folder(const std::filesystem::path& folder) {
  std::error_code ec;
  if (std::filesystem::exists(folder, ec)) {
    if (!std::filesystem::is_directory(folder, ec)) throw OutputError(folder.string() + ": exists and is not a folder");
  } else {
    check_output_folder(folder);
  }
}

int run_check_command(const CheckArgs& args) {
  if (!args.junit.empty()) check_output_folder(args.junit);
  check_failures_folder(args.failures);
  CheckOptions options;
  options.scenes = chosen_scenes(args.cases);
  options.width = args.width.value_or(options.width);
  options.height = args.height.value_or(options.height);
  options.render = render_options(nullptr, &args.gpu, &args.cpu);

  CheckReport report(args, options);
  // A scene that cannot load is reported as its first case.
  options.on_scene = [&](const std::filesystem::path& scene) {
    report.running({scene, InlineScene::never, options.samples_per_pixel.front()});
  };
  options.on_case = [&](const CheckCase& c) { report.running(c); };
  options.on_result = [&](const CheckResult& r) { report.add(r); };
  try {
    Session session(session_options(args.device));
    report.opened(session.device_info());
    run_check(session, options);
    session.close();
  } catch (const Cancelled&) {
    throw;  // Ctrl-C: no report
  } catch (const Error& e) {
    // The report so far, with the case that could not run, then the error as any command reports it.
    report.error(e.what());
    try {
      report.finish();
    } catch (const Error& also) {
      std::cerr << "vkray: " << also.what() << "\n";
    }
    throw;
  }
  report.finish();
  return report.failed() ? kExitParityFailed : kExitOk;
}

}  // namespace

Command add_check_command(CLI::App& app) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* command = app.add_subcommand(
      "check",
      "Test a device and its driver: render every shipped scene and the adversarial cases (grazing rays, shared "
      "edges, a light on a surface, scenes at the coordinate limit, ...) on both GPU paths at 1 and 16 spp against "
      "the CPU reference; one line per case; exit 4 if any case fails.");
  add_device_flags(*command, args->device);
  add_gpu_flags(*command, args->gpu, /*inline_scene=*/false);
  add_cpu_flags(*command, args->cpu, "CPU reference threads (default: one per hardware thread)");
  command->add_option("--width", args->width, "Image width of every case (default 256)")->check(within(kWidthArgument));
  command->add_option("--height", args->height, "Image height of every case (default 256)")->check(within(kHeightArgument));
  command->add_option("--case", args->cases, "Run only this scene's cases (the file's name without .json); repeatable");
  command->add_option("--junit", args->junit, "Also write the results as JUnit XML, for CI systems");
  command->add_option("--failures", args->failures, "Folder for the heatmaps of failing cases (default vkray-check-failures)");
  command->add_flag("--json", args->json, "Print the results as one JSON object on stdout (and nothing else)");
  command->footer(kExitCodes);
  return {command, [args] { return run_check_command(*args); }};
}

}  // namespace vkray::cli
