// A compute shader's descriptor set as one table: each binding's number, descriptor type and name,
// written once (vk_mini_path_tracer's DescriptorSetContainer). The set layout, the pool sizes and
// the writes are derived from the table, and a compiled shader's own declarations are checked
// against it, so a binding cannot be bound as one thing and declared as another.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <variant>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/shader_compiler.h"

namespace vkray::gpu {

struct BindingSlot {
  uint32_t binding;
  vk::DescriptorType type;  // a buffer (uniform, storage) or a texel buffer (uniform, storage)
  const char* name;         // as the shader names it, for messages
};

// A descriptor set written with a resource for every binding of its table, and the pool it came from.
class DescriptorSet {
 public:
  vk::DescriptorSet get() const { return *sets_[0]; }

 private:
  friend class DescriptorWriter;
  DescriptorSet(vk::raii::DescriptorPool pool, vk::raii::DescriptorSets sets)
      : pool_(std::move(pool)), sets_(std::move(sets)) {}
  vk::raii::DescriptorPool pool_;  // declared first: the set is freed before its pool goes
  vk::raii::DescriptorSets sets_;
};

class DescriptorTable;

// Collects one resource per binding, then allocates and writes a set: buffer() for the buffer
// bindings, texel_buffer() for the texel buffer ones.
class DescriptorWriter {
 public:
  DescriptorWriter& buffer(uint32_t binding, vk::Buffer buffer);
  DescriptorWriter& texel_buffer(uint32_t binding, vk::BufferView view);
  // Throws InternalError when a binding of the table has no resource, or got one of the wrong kind.
  DescriptorSet write() const;

 private:
  friend class DescriptorTable;
  explicit DescriptorWriter(const DescriptorTable& table) : table_(&table) {}
  const DescriptorTable* table_;
  std::vector<std::pair<uint32_t, std::variant<vk::Buffer, vk::BufferView>>> resources_;
};

class DescriptorTable {
 public:
  DescriptorTable(const vk::raii::Device& device, std::span<const BindingSlot> slots);

  const vk::raii::DescriptorSetLayout& layout() const { return layout_; }
  DescriptorWriter writer() const { return DescriptorWriter(*this); }

  // Throws ShaderError naming `entry` when the shader declares a binding the table does not have,
  // or declares one with another descriptor type than the table's.
  void check(const CompiledShader& shader, const std::filesystem::path& entry) const;

 private:
  friend class DescriptorWriter;
  const BindingSlot* find(uint32_t binding) const;

  const vk::raii::Device* device_;
  std::vector<BindingSlot> slots_;
  vk::raii::DescriptorSetLayout layout_{nullptr};
};

}  // namespace vkray::gpu
