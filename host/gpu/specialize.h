// A pipeline variant's SPIR-V with its specialization constants applied on the host: the constants
// become the variant's values, and the code they switch off is gone before the driver sees it.
//
// Drivers fold specialization constants themselves, but llvmpipe (Mesa 22.3) first inlines and
// optimizes every function trace.comp has (about 1.6 s on 2 cores for the full shader); without the
// code the variant cannot reach it takes tens of milliseconds. SPIRV-Tools' optimizer does the
// removal in about 50 ms, and only dead-code passes run: no arithmetic is rewritten, so a pixel's
// value should not depend on which of the two the driver was given (VKRAY_SPECIALIZE=driver gives
// it the whole module; tests/render_test.cpp compares the two).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

namespace vkray::gpu {

// `spirv` with each boolean specialization constant whose SpecId is a key of `values` frozen to that
// value (the rest to their defaults), and the branches, functions and instructions that became
// unreachable or unused removed. None when the optimizer refuses the module (then the caller
// specializes through VkSpecializationInfo instead, as the result would be the same). The last few
// results are remembered, so that one prepared ahead (gpu::prepare_inline_variant) costs nothing
// when the pipeline asks for it.
std::optional<std::vector<uint32_t>> specialize(const std::vector<uint32_t>& spirv, const std::map<uint32_t, bool>& values);

}  // namespace vkray::gpu
