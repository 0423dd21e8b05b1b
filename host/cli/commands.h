// The subcommands behind `vkray ...`. Each returns the process exit code or throws one of the
// errors in errors.h, which main() turns into a message and an exit code.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "packing/inline_scene.h"
#include "scene/scene.h"

namespace vkray {

// Options shared by every command that renders.
struct RenderFlags {
  std::filesystem::path scene;  // empty: the default scene
  std::optional<uint32_t> width, height, spp;
  std::string device;
  std::filesystem::path shader_dir;  // empty: the installed (or source-tree) shaders
  bool validate = false;
  unsigned threads = 0;  // CPU reference threads; 0: one per hardware thread
  uint32_t tile_timeout_ms = 60000;  // longest one GPU submission may take
  gpu::InlineScene inline_scene = gpu::InlineScene::automatic;
};

struct RenderCommand {
  RenderFlags flags;
  std::filesystem::path output;  // empty: <scene name>.png in the current folder
  std::string renderer = "gpu";  // "gpu" or "cpu"
  bool quiet = false;
};

struct ParityCommand {
  RenderFlags flags;
  std::filesystem::path diff;  // where to write the difference heatmap; empty: none
  bool json = false;
};

struct WatchCommand {
  RenderFlags flags;
  std::filesystem::path output;         // empty: <scene name>.png in the current folder
  std::optional<uint32_t> exit_after;   // test hook: stop after this many reloads
};

// Throws OutputError, before any rendering, when `output` cannot be written (unknown extension,
// missing folder).
void check_output_path(const std::filesystem::path& output);

// The scene's image settings with the command line's overrides applied.
ImageSettings image_settings(const Scene& scene, const RenderFlags& flags);

struct BenchCommand {
  std::vector<std::string> scenes{"cornell", "bunny", "dragon", "dragon-field"};  // in scenes/
  uint32_t width = 1024, height = 1024;
  unsigned repeat = 3;
  unsigned threads = 0;  // CPU reference and Embree threads; 0: one per hardware thread
  std::string device;
  std::filesystem::path shader_dir;  // empty: the installed (or source-tree) shaders
  gpu::InlineScene inline_scene = gpu::InlineScene::automatic;
  bool cpu_reference = true;
  bool embree = true;
  bool json = false;
};

int run_render(const RenderCommand& command);
int run_bench(const BenchCommand& command);
int run_watch(const WatchCommand& command);
int run_parity(const ParityCommand& command);
int run_devices();

}  // namespace vkray
