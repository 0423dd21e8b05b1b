#include "gpu/descriptors.h"

#include <algorithm>
#include <map>
#include <string>

#include "base/check.h"
#include "base/errors.h"

namespace vkray::gpu {
namespace {

bool is_texel_buffer(vk::DescriptorType type) {
  return type == vk::DescriptorType::eUniformTexelBuffer || type == vk::DescriptorType::eStorageTexelBuffer;
}

// "uniform texel buffer", as a shader author would say it.
std::string describe(vk::DescriptorType type) {
  switch (type) {
    case vk::DescriptorType::eUniformBuffer: return "uniform block";
    case vk::DescriptorType::eStorageBuffer: return "buffer block";
    case vk::DescriptorType::eUniformTexelBuffer: return "samplerBuffer (uniform texel buffer)";
    case vk::DescriptorType::eStorageTexelBuffer: return "imageBuffer (storage texel buffer)";
    default: return vk::to_string(type);
  }
}

}  // namespace

DescriptorTable::DescriptorTable(const vk::raii::Device& device, std::span<const BindingSlot> slots)
    : device_(&device), slots_(slots.begin(), slots.end()) {
  std::vector<vk::DescriptorSetLayoutBinding> bindings;
  for (const BindingSlot& slot : slots_) {
    VKRAY_CHECK(std::count_if(slots_.begin(), slots_.end(), [&](const BindingSlot& s) { return s.binding == slot.binding; }) == 1,
                "a binding number appears twice in a descriptor table");
    bindings.push_back({slot.binding, slot.type, 1, vk::ShaderStageFlagBits::eCompute});
  }
  layout_ = vk::raii::DescriptorSetLayout(device, vk::DescriptorSetLayoutCreateInfo({}, bindings));
}

const BindingSlot* DescriptorTable::find(uint32_t binding) const {
  const auto it = std::find_if(slots_.begin(), slots_.end(), [&](const BindingSlot& s) { return s.binding == binding; });
  return it == slots_.end() ? nullptr : &*it;
}

void DescriptorTable::check(const CompiledShader& shader, const std::filesystem::path& entry) const {
  std::string problems;
  for (const ShaderBinding& declared : shader.bindings) {
    const BindingSlot* slot = find(declared.binding);
    if (declared.set != 0) {
      problems += entry.string() + ": error: '" + declared.name + "' is declared in descriptor set " +
                  std::to_string(declared.set) + "; vkray binds set 0 only\n";
    } else if (!slot) {
      std::string bound;
      for (const BindingSlot& s : slots_) bound += (bound.empty() ? "" : ", ") + std::to_string(s.binding) + " " + s.name;
      problems += entry.string() + ": error: '" + declared.name + "' is declared at binding " +
                  std::to_string(declared.binding) + ", where vkray binds nothing (it binds " + bound + ")\n";
    } else if (declared.type != slot->type) {
      problems += entry.string() + ": error: '" + declared.name + "' at binding " + std::to_string(declared.binding) +
                  " is declared as " + (declared.type ? "a " + describe(*declared.type) : std::string("another kind of resource")) +
                  "; vkray binds a " + describe(slot->type) + " there (" + slot->name + ", shaders/shared/types.h)\n";
    } else if (declared.count != 1) {
      problems += entry.string() + ": error: '" + declared.name + "' at binding " + std::to_string(declared.binding) +
                  " is an array of " + std::to_string(declared.count) + "; vkray binds one " + describe(slot->type) +
                  " there\n";
    }
  }
  if (!problems.empty()) {
    problems.pop_back();
    throw ShaderError(problems);
  }
}

DescriptorWriter& DescriptorWriter::buffer(uint32_t binding, vk::Buffer buffer) {
  resources_.emplace_back(binding, buffer);
  return *this;
}

DescriptorWriter& DescriptorWriter::texel_buffer(uint32_t binding, vk::BufferView view) {
  resources_.emplace_back(binding, view);
  return *this;
}

DescriptorSet DescriptorWriter::write() const {
  const DescriptorTable& table = *table_;
  VKRAY_CHECK(resources_.size() == table.slots_.size(), "a descriptor set was written with too few or too many resources");
  // Every pointer below must stay put until updateDescriptorSets: reserve first.
  std::vector<vk::DescriptorBufferInfo> buffer_infos;
  std::vector<vk::BufferView> views;
  buffer_infos.reserve(resources_.size());
  views.reserve(resources_.size());
  std::map<vk::DescriptorType, uint32_t> counts;
  for (const BindingSlot& slot : table.slots_) ++counts[slot.type];
  std::vector<vk::DescriptorPoolSize> pool_sizes;
  for (const auto& [type, count] : counts) pool_sizes.emplace_back(type, count);
  // eFreeDescriptorSet: vk::raii::DescriptorSets frees its set when destroyed.
  vk::raii::DescriptorPool pool(*table.device_, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, pool_sizes));
  const vk::DescriptorSetLayout layout = *table.layout_;
  vk::raii::DescriptorSets sets(*table.device_, vk::DescriptorSetAllocateInfo(*pool, layout));

  std::vector<vk::WriteDescriptorSet> writes;
  for (const auto& entry : resources_) {
    const uint32_t binding = entry.first;
    const auto& resource = entry.second;
    const BindingSlot* slot = table.find(binding);
    VKRAY_CHECK(slot != nullptr, "a descriptor written at a binding its table does not have");
    VKRAY_CHECK(std::count_if(resources_.begin(), resources_.end(), [&](const auto& r) { return r.first == binding; }) == 1,
                "a binding written twice");
    vk::WriteDescriptorSet write(*sets[0], binding, 0, 1, slot->type);
    if (is_texel_buffer(slot->type)) {
      VKRAY_CHECK(std::holds_alternative<vk::BufferView>(resource), "a texel buffer binding given a buffer");
      write.setPTexelBufferView(&views.emplace_back(std::get<vk::BufferView>(resource)));
    } else {
      VKRAY_CHECK(std::holds_alternative<vk::Buffer>(resource), "a buffer binding given a texel buffer view");
      write.setPBufferInfo(&buffer_infos.emplace_back(std::get<vk::Buffer>(resource), 0, VK_WHOLE_SIZE));
    }
    writes.push_back(write);
  }
  table.device_->updateDescriptorSets(writes, {});
  return DescriptorSet(std::move(pool), std::move(sets));
}

}  // namespace vkray::gpu
