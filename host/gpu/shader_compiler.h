// GLSL compute shaders to SPIR-V at run time with glslang's C++ API, with #include support.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/shader_includes.h"

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

// Compiles `entry` for Vulkan 1.2, its #include directives resolved as gpu/shader_includes.h says.
// Throws ShaderError whose message has one line per problem, "file:line: error: message", where
// file is the file that has the error (an included file too; "x (generated)" for generated code).
CompiledShader compile_compute_shader(const std::filesystem::path& entry,
                                      const std::vector<std::filesystem::path>& include_dirs = {},
                                      const std::vector<GeneratedInclude>& generated = {});

}  // namespace vkray::gpu
