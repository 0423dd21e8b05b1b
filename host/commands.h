// The subcommands behind `vkray ...`. Each returns the process exit code or throws one of the
// errors in errors.h, which main() turns into a message and an exit code.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace vkray {

struct RenderCommand {
  std::filesystem::path scene;   // empty: the default scene
  std::filesystem::path output;  // empty: <scene name>.png in the current folder
  std::optional<uint32_t> width, height, spp;
  std::string device;
  std::filesystem::path shader_dir;  // empty: the installed (or source-tree) shaders
  bool validate = false;
  bool quiet = false;
};

int run_render(const RenderCommand& command);
int run_devices();

}  // namespace vkray
