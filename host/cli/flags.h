// The command line's flags, in groups that commands share, and the one mapping from them to the
// library's options (session/options.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "session/options.h"

namespace vkray::cli {

// SCENE [--width W] [--height H] [--spp N]
struct SceneFlags {
  std::filesystem::path scene;  // empty: the default scene
  std::optional<uint32_t> width, height, spp;
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
// [--threads N]
struct CpuFlags {
  unsigned threads = 0;
};

void add_scene_flags(CLI::App& command, SceneFlags& flags);
// `validate`: whether the command offers --validate (`vkray bench` measures without the layer).
void add_device_flags(CLI::App& command, DeviceFlags& flags, bool validate = true);
void add_gpu_flags(CLI::App& command, GpuFlags& flags);
void add_cpu_flags(CLI::App& command, CpuFlags& flags, const std::string& description);

// The scene file the flags name, or the default scene.
std::filesystem::path scene_file(const SceneFlags& flags);
SessionOptions session_options(const DeviceFlags& flags);
// The render options the flags ask for; a group the command does not take is null.
RenderOptions render_options(const SceneFlags* scene, const GpuFlags* gpu, const CpuFlags* cpu);

// What `vkray --help` and every command's help end with.
extern const char* const kExitCodes;

}  // namespace vkray::cli
