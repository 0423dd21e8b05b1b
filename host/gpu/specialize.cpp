#include "gpu/specialize.h"

#include <deque>
#include <mutex>
#include <string>
#include <unordered_map>

#include <spirv-tools/optimizer.hpp>

namespace vkray::gpu {
namespace {

std::optional<std::vector<uint32_t>> optimize(const std::vector<uint32_t>& spirv, const std::map<uint32_t, bool>& values) {
  std::unordered_map<uint32_t, std::string> defaults;
  for (const auto& [id, value] : values) defaults.emplace(id, value ? "true" : "false");
  spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_2);
  optimizer.SetMessageConsumer([](spv_message_level_t, const char*, const spv_position_t&, const char*) {});
  optimizer.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(defaults))
      .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
      .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
      // Twice: the first round's removals leave branches and functions the second finds dead.
      .RegisterPass(spvtools::CreateDeadBranchElimPass())
      .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
      .RegisterPass(spvtools::CreateAggressiveDCEPass())
      .RegisterPass(spvtools::CreateDeadBranchElimPass())
      .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass())
      .RegisterPass(spvtools::CreateAggressiveDCEPass());
  spvtools::OptimizerOptions options;
  options.set_run_validator(false);  // glslang's output; the validation layer checks what the driver gets
  std::vector<uint32_t> result;
  if (!optimizer.Run(spirv.data(), spirv.size(), &result, options)) return std::nullopt;
  return result;
}

struct Remembered {
  std::vector<uint32_t> spirv;
  std::map<uint32_t, bool> values;
  std::optional<std::vector<uint32_t>> result;
};

constexpr size_t kRemembered = 4;
std::mutex remembered_mutex;
std::deque<Remembered> remembered;  // newest last

}  // namespace

std::optional<std::vector<uint32_t>> specialize(const std::vector<uint32_t>& spirv, const std::map<uint32_t, bool>& values) {
  {
    const std::lock_guard lock(remembered_mutex);
    for (const Remembered& r : remembered)
      if (r.values == values && r.spirv == spirv) return r.result;
  }
  std::optional<std::vector<uint32_t>> result = optimize(spirv, values);
  const std::lock_guard lock(remembered_mutex);
  remembered.push_back({spirv, values, result});
  if (remembered.size() > kRemembered) remembered.pop_front();
  return result;
}

}  // namespace vkray::gpu
