// Shader folders for tests whose fault (a tile that outlives its timeout, a signal while tiles
// run) must happen on any device, however fast: copies of the shipped shaders (VKRAY_SHADER_DIR)
// with trace.comp changed.
#pragma once

#include <filesystem>
#include <string>

#include "support/temp_dir.h"

namespace vkray::test {

// Copies the shipped shader folder to `to` (which may exist).
void copy_shipped_shaders(const std::filesystem::path& to);

// Replaces the first `text` in `shader_dir`/trace.comp with `with`. Throws std::runtime_error when
// there is none: the shipped trace.comp changed, and the test must follow it.
void replace_in_trace(const std::filesystem::path& shader_dir, const std::string& text, const std::string& with);

// Makes every submission of a render with `shader_dir`'s trace.comp (every tile) last at least
// about 200 ms, and not unboundedly: one invocation of the tile spins on the device clock. The
// device needs VK_KHR_shader_clock with shaderDeviceClock (gpu::Context::has_device_clock());
// without it, compiling the shaders fails with a ShaderError that names the extension (the vkray
// command exits 1), so a test fails saying why instead of hanging.
void make_tiles_slow(const std::filesystem::path& shader_dir);

// The shipped shaders in a temporary folder, with make_tiles_slow() applied.
class SlowShaders {
 public:
  SlowShaders();
  const std::filesystem::path& path() const { return dir_.path(); }

 private:
  TempDir dir_;
};

}  // namespace vkray::test
