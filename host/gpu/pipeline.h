// The compute pipelines built from trace.comp: one descriptor table and pipeline layout, and a
// pipeline per ShaderVariant, each compiled the first time a render needs it.
#pragma once

#include <compare>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"
#include "gpu/descriptors.h"
#include "gpu/shader_compiler.h"
#include "shared/types.h"

namespace vkray::gpu {

// What a render needs of the shader: specialization constants, so that a pipeline has no code for
// what the render cannot use (on llvmpipe code behind an `if` costs every lane even when no lane
// takes it), and the scene's own code when it is compiled in. A member per row of
// VKRAY_SPECIALIZATION_CONSTANTS (shared/types.h), which says what each means, with its default.
struct ShaderVariant {
#define VKRAY_SHADER_VARIANT_MEMBER(id, name, member, value) bool member = value;
  VKRAY_SPECIALIZATION_CONSTANTS(VKRAY_SHADER_VARIANT_MEMBER)
#undef VKRAY_SHADER_VARIANT_MEMBER
  std::string inline_scene;  // served as shaders/inline_scene.glsl; empty: that file, and the BVH is walked
  // The material types the scene has, bit VKRAY_MATERIAL_* each (VKRAY_SPEC_MATERIALS in shared/types.h).
  uint32_t materials = ~0u;

  auto operator<=>(const ShaderVariant&) const = default;
};

// A specialization constant as the pipeline sets it: its id, its name in the shader, and the member
// of ShaderVariant that gives its value.
struct SpecConstant {
  uint32_t id;
  const char* name;
  bool ShaderVariant::*member;
};

inline constexpr SpecConstant kSpecConstants[] = {
#define VKRAY_SPEC_CONSTANT_ROW(id, name, member, value) {id, #name, &ShaderVariant::member},
    VKRAY_SPECIALIZATION_CONSTANTS(VKRAY_SPEC_CONSTANT_ROW)
#undef VKRAY_SPEC_CONSTANT_ROW
};

// What pipeline(variant) would compile for a variant with a scene compiled in, from the shaders in
// `shader_dir`, done now and without a device: the SPIR-V into `shader_cache` and its specialization
// into specialize()'s memory (gpu/specialize.h), where the pipeline finds them. A reload runs it beside
// its compile of trace.comp. Throws ShaderError as compiling does.
void prepare_inline_variant(const std::optional<std::filesystem::path>& shader_cache, const std::filesystem::path& shader_dir,
                            const ShaderVariant& variant);

class TracePipeline {
 public:
  // `shader`: shader_dir/trace.comp as compiled (compile_compute_shader); variants with a scene
  // compiled in are compiled from shader_dir when first needed. `cache` (optional) makes
  // re-creating a pipeline from SPIR-V seen before in this process cheap. Throws ShaderError when
  // the shader declares its bindings otherwise than vkray binds them, or reads the clock on a
  // device without one (Context::has_device_clock()).
  // `shader_cache`: where variants with a scene compiled in keep their SPIR-V (gpu/shader_cache.h).
  TracePipeline(std::shared_ptr<const Context> ctx, std::filesystem::path shader_dir, CompiledShader shader,
                std::shared_ptr<const vk::raii::PipelineCache> cache = nullptr,
                std::optional<std::filesystem::path> shader_cache = std::nullopt);
  ~TracePipeline();

  const DescriptorTable& descriptors() const { return descriptors_; }
  const vk::raii::PipelineLayout& layout() const { return layout_; }
  // trace.comp as compiled: the files it read, and its SPIR-V (a reload compares it).
  const CompiledShader& shader() const { return shader_; }

  // The pipeline for `variant`, compiled now if not kept from before. Throws ShaderError when the
  // shaders do not compile with a scene's generated code (a shader folder whose traversal.glsl no
  // longer fits the contract in inline_scene.glsl). The few most recent variants with a scene
  // compiled in are kept.
  std::shared_ptr<const vk::raii::Pipeline> pipeline(const ShaderVariant& variant) const;
  // Drops the variants with a scene compiled in (their code comes from the shader files, which may
  // have changed though this SPIR-V did not); a render that holds one keeps it.
  void forget_inline_variants() const;
  // The variant of the pipeline made last with a scene compiled in (none: no such pipeline).
  std::optional<ShaderVariant> newest_inline_variant() const;

 private:
  std::shared_ptr<const vk::raii::Pipeline> create(const ShaderVariant& variant) const;
  // Throws ShaderError for a shader this pipeline layout or this device cannot run.
  void check(const CompiledShader& shader) const;

  std::shared_ptr<const Context> ctx_;  // first: destroyed last
  std::shared_ptr<const vk::raii::PipelineCache> cache_;
  std::filesystem::path shader_dir_;
  std::optional<std::filesystem::path> shader_cache_;
  CompiledShader shader_;
  DescriptorTable descriptors_;
  vk::raii::PipelineLayout layout_{nullptr};
  vk::raii::ShaderModule module_{nullptr};
  bool specialize_on_host_;  // VKRAY_SPECIALIZE, read when made
  mutable std::mutex mutex_;
  mutable std::map<ShaderVariant, std::shared_ptr<const vk::raii::Pipeline>> pipelines_;
  mutable std::deque<ShaderVariant> inline_order_;  // variants with a scene compiled in, oldest first
};

}  // namespace vkray::gpu
