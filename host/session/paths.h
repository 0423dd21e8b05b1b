// Where vkray finds its shaders, scenes and check cases: where an installed vkray keeps them
// (<prefix>/share/vkray/..., found from <prefix>/bin/vkray or from the Python module in
// <prefix>/lib/pythonX.Y/site-packages/vkray/), else in the source tree it was built from.
#pragma once

#include <filesystem>

namespace vkray {

// The running program's own file (empty when /proc is not there).
std::filesystem::path executable_path();
std::filesystem::path default_shader_dir();
std::filesystem::path default_scene_dir();
std::filesystem::path default_scene();
std::filesystem::path default_check_dir();  // the adversarial cases of `vkray check`

}  // namespace vkray
