#include "cli/flags.h"

#include <algorithm>
#include <map>

#include "base/errors.h"
#include "image/aovs.h"
#include "image/image_file.h"

#include "session/paths.h"

namespace vkray::cli {

const std::string kExitCodes = exit_codes_help();

namespace {

constexpr const char* kLimitCheck = "limit";

// Whether the option has a within() check, which says what is wrong with a negative number.
bool has_limit(CLI::Option& option) {
  try {
    option.get_validator(kLimitCheck);
    return true;
  } catch (const CLI::OptionNotFound&) {
    return false;
  }
}

}  // namespace

CLI::Validator within(const ArgumentLimit& limit) {
  return CLI::Validator(
      [limit](std::string& text) -> std::string { return limit.problem(text); },  // the library's reading, for every face
      "UINT in [" + std::to_string(limit.min) + " - " + std::to_string(limit.max) + "]", kLimitCheck);
}

void add_scene_flags(CLI::App& command, SceneFlags& flags) {
  command.add_option("scene", flags.scene, "Scene file (default: the Cornell box, scenes/cornell.json)");
  command.add_option("--environment", flags.environment,
                     "Light the scene by this environment map (.hdr or .exr, equirectangular), in place of its own "
                     "environment and background");
  command
      .add_option("--environment-sampling", flags.environment_sampling,
                  "How the path integrator finds the environment map: importance (directions drawn from the map, weighed "
                  "against BSDF sampling; the default) or bsdf (BSDF sampling alone: to measure what importance sampling buys)")
      ->check(CLI::IsMember({"importance", "bsdf"}));
  command.add_option("--width", flags.width, "Image width in pixels (overrides the scene)")->check(within(kWidthArgument));
  command.add_option("--height", flags.height, "Image height in pixels (overrides the scene)")->check(within(kHeightArgument));
  command.add_option("--spp", flags.spp, "Samples per pixel (overrides the scene)")->check(within(kSppArgument));
  command
      .add_option("--seed", flags.seed,
                  "Seed of the sample streams (overrides the scene's; default 0): renders with different seeds are "
                  "independent and can be averaged")
      ->check(within(kSeedArgument));
}

void add_region_flag(CLI::App& command, SceneFlags& flags) {
  command
      .add_option_function<std::string>(
          "--region", [&flags](const std::string& text) { flags.region = parse_region(text); },
          "Render only part of the image, as a part for `vkray merge` (.exr or .pfm): X0,Y0,X1,Y1 (pixel bounds in the "
          "full image, half-open) or I/N (band I of N bands of whole rows of about equal work, from 0). Each pixel is "
          "the same as in the full render")
      ->option_text("X0,Y0,X1,Y1|I/N")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            try {
              parse_region(text);
              return "";
            } catch (const UsageError& e) {
              return e.what();
            }
          },
          ""));
}

void add_device_flags(CLI::App& command, DeviceFlags& flags, bool validate) {
  command.add_option("--device", flags.device, "Vulkan device: index or part of its name (see `vkray devices`)");
  command.add_option("--shader-dir", flags.shader_dir, "Folder with trace.comp and its includes");
  if (validate) command.add_flag("--validate", flags.validate, "Enable the Khronos validation layer; any message is an error");
}

void add_gpu_flags(CLI::App& command, GpuFlags& flags, bool inline_scene) {
  command
      .add_option("--tile-timeout", flags.tile_timeout_ms,
                  "Longest one GPU submission (a tile) may run, in milliseconds, before the render fails with exit 3 "
                  "(default 60000)")
      ->check(within(kTileTimeoutArgument));
  if (!inline_scene) return;
  static const std::map<std::string, InlineScene> names{
      {"auto", InlineScene::automatic}, {"always", InlineScene::always}, {"never", InlineScene::never}};
  command
      .add_option_function<std::string>(
          "--inline-scene", [&flags](const std::string& name) { flags.inline_scene = names.at(name); },
          "GPU path for scenes of at most 64 primitives: compile the scene into the shader (every primitive "
          "tested, no BVH) 'always', 'never', or 'auto' (default: when the render has at least 2^17 camera rays "
          "per primitive under `path`, more past 44 primitives, 2^19 under `direct` and only up to 32 "
          "primitives, so that the longer compile pays off)")
      ->option_text("auto|always|never")
      ->check(CLI::IsMember({"auto", "always", "never"}));
}

void add_cpu_flags(CLI::App& command, CpuFlags& flags, const std::string& description) {
  command.add_option("--threads", flags.threads, description)->check(within(kThreadsArgument));
}

void add_display_flags(CLI::App& command, DisplayFlags& flags) {
  command
      .add_option_function<std::string>(
          "--tonemap", [&flags](const std::string& name) { flags.display.tonemap = *parse_tonemap(name); },
          "How a PNG shows radiance: 'none' (default: clamped to [0, 1], then sRGB), 'aces' (ACES filmic, "
          "Hill's fit) or 'pbr-neutral' (Khronos PBR Neutral); EXR and PFM files stay linear")
      ->option_text("none|aces|pbr-neutral")
      ->check(CLI::IsMember({"none", "aces", "pbr-neutral"}));
  command
      .add_option("--exposure", flags.display.exposure,
                  "Exposure of a PNG in stops: radiance times 2^EV before the tone mapper (default 0)")
      ->option_text("EV")
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            float stops = 0.0f;
            if (!CLI::detail::lexical_cast(value, stops) || !(std::abs(stops) <= kMaxExposure))
              return "expected a number of stops from -64 to 64, got \"" + printable(value) + "\"";
            return "";
          },
          ""));
}

void add_exr_flags(CLI::App& command, ExrFlags& flags, const std::string& aov_help) {
  command.add_option("--aov", flags.aovs, aov_help + ", comma-separated: albedo, normal, position, depth, object");
  command.add_flag("--exr-float", flags.exr_float, "Write an .exr with 32-bit float channels instead of 16-bit half");
}

OutputContent output_content(const std::filesystem::path& output, const ExrFlags& exr, const DisplayFlags& display) {
  OutputContent content;
  content.full_float = exr.exr_float;
  content.display = display.display;
  check_output_image(output);
  if (!exr.aovs.empty()) content.passes = parse_aov_list(exr.aovs);
  return content;
}

void apply_value_rules(CLI::App& app) {
  // `limited`: a negative number is left for the limit to refuse.
  const auto decimal = [](bool limited) {
    return CLI::Validator(
        [limited](std::string& value) -> std::string {
          const size_t start = limited && value.starts_with('-') ? 1 : 0;
          if (value.size() == start || value.find_first_not_of("0123456789", start) != std::string::npos)
            return "expected a decimal integer, got \"" + printable(value) + "\"";
          if (start == 0) value.erase(0, std::min(value.find_first_not_of('0'), value.size() - 1));
          return "";
        },
        "");
  };
  const CLI::Validator not_empty([](std::string& value) { return value.empty() ? "the value is empty" : ""; }, "");
  for (CLI::App* command : app.get_subcommands({})) {
    apply_value_rules(*command);
    for (CLI::Option* option : command->get_options()) {
      if (option->get_expected_min() == 0) continue;  // a flag
      // "UINT", or "UINT:INT in [1 - 16384]" with a range check.
      const std::string type = option->get_type_name().substr(0, option->get_type_name().find(':'));
      if (type == "INT" || type == "UINT") option->transform(decimal(has_limit(*option)));
      else if (type == "TEXT") option->check(not_empty);
    }
  }
}

std::filesystem::path scene_file(const SceneFlags& flags) { return flags.scene.empty() ? default_scene() : flags.scene; }

SessionOptions session_options(const DeviceFlags& flags) {
  SessionOptions options;
  options.device = flags.device;
  options.validation = flags.validate;
  options.shader_dir = flags.shader_dir;
  return options;
}

RenderOptions render_options(const SceneFlags* scene, const GpuFlags* gpu, const CpuFlags* cpu) {
  RenderOptions options;
  if (scene) {
    options.width = scene->width;
    options.height = scene->height;
    options.samples_per_pixel = scene->spp;
    options.seed = scene->seed;
    options.region = scene->region;
    options.sample_environment = scene->environment_sampling == "importance";
  }
  if (gpu) {
    options.tile_timeout = std::chrono::milliseconds(gpu->tile_timeout_ms);
    options.inline_scene = gpu->inline_scene;
  }
  if (cpu) options.threads = cpu->threads;
  return options;
}

}  // namespace vkray::cli
