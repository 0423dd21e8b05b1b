#include "gpu/pipeline.h"

#include <algorithm>
#include <cstdlib>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glslang/SPIRV/spirv.hpp>

#include "base/errors.h"
#include "gpu/shader_cache.h"
#include "gpu/specialize.h"
#include "shared/materials.h"
#include "shared/types.h"

namespace vkray::gpu {
namespace {

// Pipelines kept for scenes compiled in (`vkray watch` makes one for every edit of a small scene).
constexpr size_t kKeptInlinePipelines = 4;

constexpr vk::DescriptorType kTexel = vk::DescriptorType::eUniformTexelBuffer;

// The descriptor set shaders/trace.comp declares (binding numbers from shared/types.h).
constexpr BindingSlot kTraceBindings[] = {
    {VKRAY_BINDING_FRAME, vk::DescriptorType::eUniformBuffer, "frame"},
    {VKRAY_BINDING_PRIMITIVES, kTexel, "primitives"},
    {VKRAY_BINDING_NORMALS, kTexel, "normals"},
    {VKRAY_BINDING_NODES, kTexel, "nodes"},
    {VKRAY_BINDING_MATERIALS, kTexel, "materials"},
    {VKRAY_BINDING_LIGHTS, kTexel, "lights"},
    {VKRAY_BINDING_OUTPUT, vk::DescriptorType::eStorageBuffer, "output"},
    {VKRAY_BINDING_EMITTERS, kTexel, "emitters"},
    {VKRAY_BINDING_AOVS, vk::DescriptorType::eStorageBuffer, "aovs"},
    {VKRAY_BINDING_TEXCOORDS, kTexel, "texcoords"},
    {VKRAY_BINDING_TEXTURES, kTexel, "textures"},
    {VKRAY_BINDING_TANGENTS, kTexel, "tangents"},
    {VKRAY_BINDING_COLOURS, kTexel, "colours"},
    {VKRAY_BINDING_INSTANCES, kTexel, "instances"},
    {VKRAY_BINDING_ENVIRONMENT, kTexel, "environment"},
    {VKRAY_BINDING_ENVIRONMENT_CDF, kTexel, "environment_cdf"},
};

// Two rows of one id would give the shader's constant whichever value Vulkan takes first.
constexpr bool distinct_ids(std::span<const SpecConstant> table) {
  for (size_t i = 0; i < table.size(); ++i)
    for (size_t j = i + 1; j < table.size(); ++j)
      if (table[i].id == table[j].id) return false;
  return true;
}
static_assert(distinct_ids(kSpecConstants), "a specialization constant id appears twice in VKRAY_SPECIALIZATION_CONSTANTS");
static_assert(std::all_of(std::begin(kSpecConstants), std::end(kSpecConstants), [](const SpecConstant& c) { return c.id < VKRAY_SPEC_MATERIALS; }),
              "a specialization constant takes an id of the material types'");
static_assert(VKRAY_MATERIAL_TYPE_COUNT <= 32, "ShaderVariant::materials holds a bit per material type");

// Whether a SPIR-V module declares `capability` (its OpCapability instructions come first).
bool declares(const std::vector<uint32_t>& spirv, spv::Capability capability) {
  constexpr size_t kHeaderWords = 5;
  for (size_t at = kHeaderWords; at < spirv.size();) {
    const uint32_t words = spirv[at] >> spv::WordCountShift, opcode = spirv[at] & spv::OpCodeMask;
    if (opcode == spv::OpCapability && words == 2 && at + 1 < spirv.size() && spirv[at + 1] == uint32_t(capability))
      return true;
    if (words == 0) break;
    at += words;
  }
  return false;
}

// VKRAY_SPECIALIZE (docs/commands.md): `host` (the default) applies the specialization constants to
// the SPIR-V before the driver sees it; `driver` gives the driver the whole module and the values.
bool specialize_on_host() {
  const char* setting = std::getenv("VKRAY_SPECIALIZE");
  if (!setting || std::string_view(setting) == "host") return true;
  if (std::string_view(setting) == "driver") return false;
  throw UsageError(std::string("VKRAY_SPECIALIZE is '") + setting + "'; it takes host (the default) or driver");
}

// Each specialization constant's value for `variant`, by SpecId.
std::map<uint32_t, bool> specialization_values(const ShaderVariant& variant) {
  std::map<uint32_t, bool> values;
  for (const SpecConstant& c : kSpecConstants) values[c.id] = variant.*c.member;
  for (uint32_t type = 0; type < VKRAY_MATERIAL_TYPE_COUNT; ++type) values[VKRAY_SPEC_MATERIALS + type] = (variant.materials >> type) & 1u;
  return values;
}

CompiledShader compile_inline_variant(const std::optional<std::filesystem::path>& shader_cache, const std::filesystem::path& shader_dir,
                                      const ShaderVariant& variant) {
  return compile_compute_shader_cached(shader_cache, shader_dir / "trace.comp", {shader_dir}, {{"inline_scene.glsl", variant.inline_scene}});
}

}  // namespace

void prepare_inline_variant(const std::optional<std::filesystem::path>& shader_cache, const std::filesystem::path& shader_dir,
                            const ShaderVariant& variant) {
  specialize(compile_inline_variant(shader_cache, shader_dir, variant).spirv, specialization_values(variant));
}

TracePipeline::TracePipeline(std::shared_ptr<const Context> ctx, std::filesystem::path shader_dir,
                             CompiledShader shader, std::shared_ptr<const vk::raii::PipelineCache> cache,
                             std::optional<std::filesystem::path> shader_cache)
    : ctx_(std::move(ctx)),
      cache_(std::move(cache)),
      shader_dir_(std::move(shader_dir)),
      shader_cache_(std::move(shader_cache)),
      shader_(std::move(shader)),
      descriptors_(ctx_->device(), kTraceBindings),
      specialize_on_host_(specialize_on_host()) {
  check(shader_);
  const vk::PushConstantRange push(vk::ShaderStageFlagBits::eCompute, 0, sizeof(TileConstants));
  const vk::DescriptorSetLayout set_layout = *descriptors_.layout();
  layout_ = vk::raii::PipelineLayout(ctx_->device(), vk::PipelineLayoutCreateInfo({}, set_layout, push));
  module_ = vk::raii::ShaderModule(ctx_->device(), vk::ShaderModuleCreateInfo({}, shader_.spirv));
}

TracePipeline::~TracePipeline() = default;

std::shared_ptr<const vk::raii::Pipeline> TracePipeline::pipeline(const ShaderVariant& variant) const {
  const std::lock_guard lock(mutex_);
  if (const auto found = pipelines_.find(variant); found != pipelines_.end()) {
    if (!variant.inline_scene.empty()) {  // the most recently used is kept longest, and prepared on a reload
      inline_order_.erase(std::find(inline_order_.begin(), inline_order_.end(), variant));
      inline_order_.push_back(variant);
    }
    return found->second;
  }
  auto created = create(variant);
  if (!variant.inline_scene.empty()) {
    inline_order_.push_back(variant);
    if (inline_order_.size() > kKeptInlinePipelines) {  // a render still using it holds its own reference
      pipelines_.erase(inline_order_.front());
      inline_order_.pop_front();
    }
  }
  return pipelines_.emplace(variant, std::move(created)).first->second;
}

void TracePipeline::forget_inline_variants() const {
  const std::lock_guard lock(mutex_);
  for (const ShaderVariant& variant : inline_order_) pipelines_.erase(variant);
  inline_order_.clear();
}

std::optional<ShaderVariant> TracePipeline::newest_inline_variant() const {
  const std::lock_guard lock(mutex_);
  if (inline_order_.empty()) return std::nullopt;
  return inline_order_.back();
}

void TracePipeline::check(const CompiledShader& shader) const {
  const std::filesystem::path entry = shader_dir_ / "trace.comp";
  descriptors_.check(shader, entry);
  // A module with a capability the device did not enable is invalid usage, not an error the
  // driver reports: refuse it here, where the user can be told why.
  if (!ctx_->has_device_clock() && declares(shader.spirv, spv::CapabilityShaderClockKHR))
    throw ShaderError(entry.string() + ": error: the shaders read the clock (GL_EXT_shader_realtime_clock or " +
                      "GL_ARB_shader_clock), and " + ctx_->device_name() +
                      " has no VK_KHR_shader_clock with shaderDeviceClock");
}

std::shared_ptr<const vk::raii::Pipeline> TracePipeline::create(const ShaderVariant& variant) const {
  // A scene compiled in is a module of its own.
  std::optional<CompiledShader> inline_shader;
  if (!variant.inline_scene.empty()) {
    inline_shader = compile_inline_variant(shader_cache_, shader_dir_, variant);
    check(*inline_shader);
  }
  const std::map<uint32_t, bool> by_id = specialization_values(variant);
  std::vector<VkBool32> values;
  std::vector<vk::SpecializationMapEntry> entries;
  for (const auto& [id, value] : by_id) {
    entries.emplace_back(id, uint32_t(values.size() * sizeof(VkBool32)), sizeof(VkBool32));
    values.push_back(value);
  }
  // The variant's own module, its constants applied (gpu/specialize.h); the module may go once the
  // pipeline exists. Where the optimizer declines, or VKRAY_SPECIALIZE=driver, the driver specializes.
  const std::vector<uint32_t>& spirv = inline_shader ? inline_shader->spirv : shader_.spirv;
  const std::optional<std::vector<uint32_t>> specialized = specialize_on_host_ ? specialize(spirv, by_id) : std::nullopt;
  vk::raii::ShaderModule own_module{nullptr};
  if (specialized) {
    own_module = vk::raii::ShaderModule(ctx_->device(), vk::ShaderModuleCreateInfo({}, *specialized));
  } else if (inline_shader) {
    own_module = vk::raii::ShaderModule(ctx_->device(), vk::ShaderModuleCreateInfo({}, inline_shader->spirv));
  }
  const vk::ShaderModule module = *own_module ? *own_module : *module_;
  const vk::SpecializationInfo specialization(entries, vk::ArrayProxyNoTemporaries<const VkBool32>(values));
  const vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, module, "main",
                                                specialized ? nullptr : &specialization);
  return std::make_shared<const vk::raii::Pipeline>(
      ctx_->device(), cache_ ? vk::Optional<const vk::raii::PipelineCache>(*cache_) : nullptr,
      vk::ComputePipelineCreateInfo({}, stage, *layout_));
}

}  // namespace vkray::gpu
