// GLSL compute shaders to SPIR-V at run time with glslang's C++ API, with #include support.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

namespace vkray::gpu {

// A resource the shader declares in a descriptor set (not its push constants), from glslang's
// reflection of the code `main` uses.
struct ShaderBinding {
  uint32_t set;
  uint32_t binding;
  std::optional<vk::DescriptorType> type;  // none: a kind of resource vkray never binds (an image, a sampler)
  uint32_t count;                          // descriptors: more than 1 for an array
  std::string name;
};

struct CompiledShader {
  std::vector<uint32_t> spirv;
  // The entry file and every file it included, once each: what a change to must trigger a rebuild.
  std::vector<std::filesystem::path> sources;
  std::vector<ShaderBinding> bindings;
};

// Text served for an #include of `name` in place of any file of that name (code the host generates).
struct GeneratedInclude {
  std::string name;  // as written in the #include
  std::string text;
};

// Compiles `entry` for Vulkan 1.2. `#include "x"` is looked up in `generated`, then next to the
// including file, then in `include_dirs` in order; `#include <x>` skips the including file's folder.
// Throws ShaderError whose message has one line per problem, "file:line: error: message", where
// file is the file that has the error (an included file too; "x (generated)" for generated code).
CompiledShader compile_compute_shader(const std::filesystem::path& entry,
                                      const std::vector<std::filesystem::path>& include_dirs = {},
                                      const std::vector<GeneratedInclude>& generated = {});

}  // namespace vkray::gpu
