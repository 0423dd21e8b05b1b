// The command line's flags, in groups that commands share, and the one mapping from them to the
// library's options (session/options.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "image/display.h"
#include "image/exr.h"
#include "session/options.h"

namespace vkray::cli {

// SCENE [--environment FILE] [--width W] [--height H] [--spp N] [--seed S] [--region X0,Y0,X1,Y1|I/N]
struct SceneFlags {
  std::filesystem::path scene;  // empty: the default scene
  std::filesystem::path environment;  // an environment map in place of the scene's; empty: none
  std::string environment_sampling = "importance";  // or "bsdf": RenderOptions::sample_environment false
  std::optional<uint32_t> width, height, spp, seed;
  std::optional<RegionRequest> region;  // offered by add_region_flag
};
// [--device D] [--validate] [--shader-dir DIR]
struct DeviceFlags {
  std::string device;
  bool validate = false;
  std::filesystem::path shader_dir;
};
// [--tile-timeout MS] [--inline-scene auto|always|never]
struct GpuFlags {
  uint32_t tile_timeout_ms = 60000;
  InlineScene inline_scene = InlineScene::automatic;
};
// [--tonemap none|aces|pbr-neutral] [--exposure EV]: how 8-bit outputs show radiance
struct DisplayFlags {
  DisplayTransform display;
};
// [--aov LIST] [--exr-float]: what an EXR output holds besides the image
struct ExrFlags {
  std::string aovs;  // first-hit passes, comma-separated (image/aovs.h)
  bool exr_float = false;
};
// [--threads N]
struct CpuFlags {
  unsigned threads = 0;
};

// The library's limit (session/options.h) as a check of a flag's text, with the library's message,
// negative numbers included ("--width: expected an integer from 1 to 16384, got -5"). What is not an
// integer at all is the decimal rule's (apply_value_rules).
CLI::Validator within(const ArgumentLimit& limit);

void add_scene_flags(CLI::App& command, SceneFlags& flags);
void add_region_flag(CLI::App& command, SceneFlags& flags);
// `validate`: whether the command offers --validate (`vkray bench` measures without the layer).
void add_device_flags(CLI::App& command, DeviceFlags& flags, bool validate = true);
// `inline_scene`: whether the command offers --inline-scene (`vkray check` runs both paths).
void add_gpu_flags(CLI::App& command, GpuFlags& flags, bool inline_scene = true);
void add_cpu_flags(CLI::App& command, CpuFlags& flags, const std::string& description);
void add_display_flags(CLI::App& command, DisplayFlags& flags);
// `aov_help`: what the command does with the passes.
void add_exr_flags(CLI::App& command, ExrFlags& flags, const std::string& aov_help);
// What an output image holds by the flags, checked in the one order every face uses: the file
// (check_output_image: its type, its folder), then the passes' names. Throws OutputError, UsageError.
OutputContent output_content(const std::filesystem::path& output, const ExrFlags& exr, const DisplayFlags& display);

// Rules every option value follows, set once for all commands by the option's type, so that no
// option can miss them: an integer is decimal digits (CLI11 alone reads "0100" as octal 64 and
// "0x40" as hex; leading zeros are dropped, so "0100" is 100), and a text or path value is not
// empty (`-o ""` is a mistake, not "the default").
void apply_value_rules(CLI::App& app);

// The scene file the flags name, or the default scene.
std::filesystem::path scene_file(const SceneFlags& flags);
SessionOptions session_options(const DeviceFlags& flags);
// The render options the flags ask for; a group the command does not take is null.
RenderOptions render_options(const SceneFlags* scene, const GpuFlags* gpu, const CpuFlags* cpu);

// What `vkray --help` and every command's help end with.
extern const std::string kExitCodes;

}  // namespace vkray::cli
