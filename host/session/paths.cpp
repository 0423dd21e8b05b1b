#include "session/paths.h"

#include <dlfcn.h>

#include <system_error>

#ifndef VKRAY_MODULE_TO_PREFIX  // built without the Python module
#define VKRAY_MODULE_TO_PREFIX "../../../.."
#endif

namespace vkray {

std::filesystem::path executable_path() {
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe;
}

namespace {

// The file this code was loaded from: the executable for the command line, the extension module
// for Python.
std::filesystem::path code_path() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&code_path), &info) != 0 && info.dli_fname && info.dli_fname[0] == '/') {
    std::error_code ec;  // glibc names the main program as it was started: a symlink is resolved here
    const auto resolved = std::filesystem::canonical(info.dli_fname, ec);
    if (!ec) return resolved;
  }
  return executable_path();
}

// Where an installed vkray keeps its data: <prefix>/share/vkray, from <prefix>/bin/vkray or from
// the Python module in <prefix>/VKRAY_PYTHON_INSTALL_DIR/vkray/ (VKRAY_MODULE_TO_PREFIX leads back).
std::filesystem::path find(const char* relative, const char* source_tree_dir, const char* probe) {
  const auto code = code_path();
  std::error_code ec;
  if (!code.empty()) {
    const auto from_bin = code.parent_path().parent_path();
    const auto from_module = (code.parent_path() / VKRAY_MODULE_TO_PREFIX).lexically_normal();
    for (const auto& prefix : {from_bin, from_module}) {
      const auto installed = prefix / "share" / "vkray" / relative;
      if (std::filesystem::exists(installed / probe, ec)) return installed;
    }
  }
  return source_tree_dir;
}

}  // namespace

std::filesystem::path default_shader_dir() { return find("shaders", VKRAY_SOURCE_SHADER_DIR, "trace.comp"); }

std::filesystem::path default_scene_dir() { return find("scenes", VKRAY_SOURCE_SCENE_DIR, "cornell.json"); }

std::filesystem::path default_scene() { return default_scene_dir() / "cornell.json"; }

std::filesystem::path default_check_dir() { return find("checks", VKRAY_SOURCE_CHECK_DIR, "light-on-surface.json"); }

}  // namespace vkray
