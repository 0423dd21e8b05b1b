// The environment map in the shader's layout (shaders/shared/scene_layout.h, "The environment map"):
// its texels with their density, and the cumulative distribution that draws them, in proportion to
// luminance times sin(theta).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray::gpu {

struct PackedEnvironment {
  // 0 when the scene has no map, or one that is black everywhere (it lights nothing and shows black,
  // as the default background does).
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> texels;  // (radiance times 2^radiance_exponent, density), row by row
  std::vector<float> cdf;         // the rows' cumulative shares, then the rows' own
};

// Built on every core; a 4096 x 2048 map in a few tens of milliseconds (tools/bench-environment).
PackedEnvironment pack_environment(const Environment& environment, int radiance_exponent);

}  // namespace vkray::gpu
