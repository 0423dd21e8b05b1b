// Runs a small test compute shader over an input storage buffer (binding 0) into an output storage
// buffer (binding 1), with the element count as a push constant: how GLSL functions are unit-tested
// on the device itself.
#pragma once

#include <filesystem>
#include <vector>

#include "gpu/context.h"

namespace vkray::test {

// The shader's local_size_x must be 64.
std::vector<float> run_kernel(const gpu::Context& ctx, const std::filesystem::path& shader, const void* input,
                              size_t input_bytes, uint32_t count, size_t outputs_per_item);

}  // namespace vkray::test
