// Where vkray finds its shaders and default scene: next to an installed executable
// (<prefix>/bin/vkray -> <prefix>/share/vkray/...), else in the source tree it was built from.
#pragma once

#include <filesystem>

namespace vkray {

std::filesystem::path default_shader_dir();
std::filesystem::path default_scene();

}  // namespace vkray
