// Lets a header under shared/ compile both as GLSL and as C++ against GLM, so that a struct, a
// constant or a small function that both sides need is written once. In C++ what such a header
// declares lands in namespace vkray::gpu, where the GLSL names below mean what they mean in GLSL.
#ifndef VKRAY_SHARED_GLSL_CPP_H
#define VKRAY_SHARED_GLSL_CPP_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
namespace vkray::gpu {
using uint = std::uint32_t;
using glm::uvec3;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using glm::floatBitsToInt;
using glm::floatBitsToUint;
using glm::intBitsToFloat;
using glm::uintBitsToFloat;
using glm::max;
using glm::min;
}  // namespace vkray::gpu
#define VKRAY_SHARED_BEGIN namespace vkray::gpu {
#define VKRAY_SHARED_END }
#define VKRAY_INLINE inline
#define VKRAY_INOUT(type) type&
#else
#define VKRAY_SHARED_BEGIN
#define VKRAY_SHARED_END
#define VKRAY_INLINE
#define VKRAY_INOUT(type) inout type
#endif

#endif  // VKRAY_SHARED_GLSL_CPP_H
