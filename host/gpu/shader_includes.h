// A shader's #include directives, resolved for glslang: where each name is looked up, which files
// were read, and what glslang does not catch by itself: a cycle (it would include forever), a chain
// too deep, a file that is not a regular file (a FIFO would block) or is too large. Needs glslang
// but no Vulkan, so that tests/fuzz/fuzz_shader_includes can drive it alone.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glslang/Public/ShaderLang.h>

#include "base/input_file.h"

namespace vkray::gpu {

// How many files deep #include may nest below the entry file, and how much one compile may include
// in all, counting a file each time it is included (files that include each other twice at each of
// 32 levels would otherwise be read 2^32 times); docs/limits.md.
constexpr size_t kMaxIncludeDepth = 32;
constexpr size_t kMaxIncludes = 4096;
constexpr uint64_t kMaxIncludedBytes = uint64_t(64) << 20;

// Text served for an #include of `name` in place of any file of that name (code the host generates).
struct GeneratedInclude {
  std::string name;  // as written in the #include
  std::string text;
};

// Reads a shader file whole: read_input_file with kMaxShaderFileBytes, or (for fuzzing) from memory.
using ShaderFileReader = std::function<InputFile(const std::filesystem::path&)>;
InputFile read_shader_file(const std::filesystem::path& file);

// `#include "x"` is looked up in `generated`, then next to the including file, then in `dirs` in
// order; `#include <x>` skips the including file's folder. A file that is on the chain of includes
// being read is a cycle, an error at the #include that closes it ("#include cycle: trace.comp ->
// a.glsl -> b.glsl -> a.glsl"), unless it has an include guard (its first directives #ifndef X and
// #define X), which makes including it again harmless. Errors are reported by glslang at the line
// of the #include.
class ShaderIncludes : public glslang::TShader::Includer {
 public:
  // `entry` is the file being compiled, as glslang names it.
  ShaderIncludes(const std::filesystem::path& entry, std::vector<std::filesystem::path> dirs,
                 const std::vector<GeneratedInclude>& generated, ShaderFileReader read = read_shader_file);

  IncludeResult* includeLocal(const char* header, const char* includer, size_t depth) override;
  IncludeResult* includeSystem(const char* header, const char* includer, size_t depth) override;
  void releaseInclude(IncludeResult* result) override;

  // The entry file and every file included, once each, in the order first read: what a change to
  // must trigger a rebuild.
  const std::vector<std::filesystem::path>& sources() const { return sources_; }

 private:
  struct Open {  // a file on the chain of includes being read
    const IncludeResult* result;  // null for the entry file
    std::string key;              // its path, or "x (generated)"
    std::string name;             // as written in the #include
  };
  IncludeResult* include(const std::string& header, const std::filesystem::path& local_dir, size_t depth);
  IncludeResult* error(const std::string& message);

  std::vector<std::filesystem::path> dirs_;
  const std::vector<GeneratedInclude>& generated_;
  ShaderFileReader read_;
  std::string entry_name_;
  std::vector<std::filesystem::path> sources_;
  std::vector<Open> chain_;
  // glslang asks includeSystem after includeLocal fails; that search is already done, so it gets
  // includeLocal's answer again.
  size_t includes_ = 0;
  uint64_t included_bytes_ = 0;
  bool local_failed_ = false;
  std::string local_error_;
};

}  // namespace vkray::gpu
