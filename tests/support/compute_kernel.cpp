#include "support/compute_kernel.h"

#include <chrono>
#include <cstring>

#include "gpu/buffer.h"
#include "gpu/descriptors.h"
#include "gpu/shader_compiler.h"

namespace vkray::test {

std::vector<float> run_kernel(const gpu::Context& ctx, const std::filesystem::path& shader, const void* input,
                              size_t input_bytes, uint32_t count, size_t outputs_per_item) {
  const auto& device = ctx.device();
  const gpu::CompiledShader compiled = gpu::compile_compute_shader(shader, {VKRAY_SHADER_DIR});
  using S = vk::ShaderStageFlagBits;
  constexpr gpu::BindingSlot kBindings[] = {{0, vk::DescriptorType::eStorageBuffer, "input"},
                                            {1, vk::DescriptorType::eStorageBuffer, "output"}};
  const gpu::DescriptorTable descriptors(device, kBindings);
  descriptors.check(compiled, shader);
  const vk::PushConstantRange push(S::eCompute, 0, sizeof(uint32_t));
  const vk::DescriptorSetLayout raw_layout = *descriptors.layout();
  const vk::raii::PipelineLayout layout(device, vk::PipelineLayoutCreateInfo({}, raw_layout, push));
  const vk::raii::ShaderModule module(device, vk::ShaderModuleCreateInfo({}, compiled.spirv));
  const vk::raii::Pipeline pipeline(device, nullptr,
                                    vk::ComputePipelineCreateInfo({}, {{}, S::eCompute, *module, "main"}, *layout));

  using M = vk::MemoryPropertyFlagBits;
  const gpu::Buffer in = gpu::upload_buffer(ctx, input, input_bytes, vk::BufferUsageFlagBits::eStorageBuffer);
  const size_t out_bytes = size_t(count) * outputs_per_item * sizeof(float);
  const gpu::Buffer out = gpu::create_buffer(ctx, out_bytes, vk::BufferUsageFlagBits::eStorageBuffer,
                                             M::eHostVisible | M::eHostCoherent);

  const gpu::DescriptorSet set = descriptors.writer().buffer(0, *in.buffer).buffer(1, *out.buffer).write();

  const vk::raii::CommandPool command_pool(device, {{}, ctx.queue_family()});
  vk::raii::CommandBuffers cbs(device, {*command_pool, vk::CommandBufferLevel::ePrimary, 1});
  const auto& cb = cbs[0];
  cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  cb.bindPipeline(vk::PipelineBindPoint::eCompute, *pipeline);
  cb.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *layout, 0, set.get(), {});
  cb.pushConstants<uint32_t>(*layout, S::eCompute, 0, count);
  cb.dispatch((count + 63) / 64, 1, 1);
  const vk::MemoryBarrier to_host(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead);
  cb.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {}, to_host, {}, {});
  cb.end();
  const vk::raii::Fence fence(device, vk::FenceCreateInfo{});
  const vk::CommandBuffer raw = *cb;
  ctx.queue().submit(vk::SubmitInfo({}, {}, raw), *fence);
  ctx.wait(fence, std::chrono::seconds(30), "test kernel");

  std::vector<float> result(count * outputs_per_item);
  std::memcpy(result.data(), out.mapped, out_bytes);
  return result;
}

}  // namespace vkray::test
