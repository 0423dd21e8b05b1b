#include "session/paths.h"

#include <system_error>

namespace vkray {

std::filesystem::path executable_path() {
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe;
}

namespace {

std::filesystem::path installed_data_dir() {
  const auto exe = executable_path();
  if (exe.empty()) return {};
  return exe.parent_path().parent_path() / "share" / "vkray";
}

std::filesystem::path find(const char* relative, const char* source_tree_dir, const char* probe) {
  const auto installed = installed_data_dir() / relative;
  std::error_code ec;
  if (std::filesystem::exists(installed / probe, ec)) return installed;
  return source_tree_dir;
}

}  // namespace

std::filesystem::path default_shader_dir() { return find("shaders", VKRAY_SOURCE_SHADER_DIR, "trace.comp"); }

std::filesystem::path default_scene_dir() { return find("scenes", VKRAY_SOURCE_SCENE_DIR, "cornell.json"); }

std::filesystem::path default_scene() { return default_scene_dir() / "cornell.json"; }

std::filesystem::path default_check_dir() { return find("checks", VKRAY_SOURCE_CHECK_DIR, "light-on-surface.json"); }

}  // namespace vkray
