// Compiled shaders kept on disk between runs. glslang takes about 0.15-0.25 s to compile trace.comp,
// most of a small render's time; a run whose shader files, generated code and vkray build are the
// same as an earlier run's reads the SPIR-V back instead.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "gpu/shader_compiler.h"

namespace vkray::gpu {

// The folder: $VKRAY_SHADER_CACHE when set (empty or "off": no cache), else
// $XDG_CACHE_HOME/vkray/shaders, else $HOME/.cache/vkray/shaders; none when neither is set.
std::optional<std::filesystem::path> shader_cache_dir();

// compile_compute_shader(), through the cache in `cache_dir` (none: compiled every time). An entry is
// used only when everything that could change the result is as it was: the vkray executable (its
// size and modification time), glslang's version, the generated includes, every file under the
// entry's folder and the include folders, and every file the shader included. Anything wrong with
// the cache (missing, unreadable, corrupt, unwritable) means compiling; it never fails a render.
// Keeps the newest kShaderCacheEntries entries.
CompiledShader compile_compute_shader_cached(const std::optional<std::filesystem::path>& cache_dir,
                                             const std::filesystem::path& entry,
                                             const std::vector<std::filesystem::path>& include_dirs = {},
                                             const std::vector<GeneratedInclude>& generated = {});

constexpr size_t kShaderCacheEntries = 64;

}  // namespace vkray::gpu
