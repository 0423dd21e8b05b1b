// Camera set-up and sample pattern shared by the GPU path and the CPU reference: the orthonormal
// basis of the scene contract and the strata of the sample pattern (shaders/shared/sampling.h).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray {

struct CameraBasis {
  glm::vec3 origin;
  glm::vec3 right;    // r = normalize(f x up)
  glm::vec3 up;       // u = r x f
  glm::vec3 forward;  // f
  float focal_px;     // F = focal_length * H
};

CameraBasis camera_basis(const Camera& camera, uint32_t image_height);

// The camera's view direction for a scene file's "direction", or its look_at minus its position:
// `d` over its float length where that is finite and non-zero, else normalized in double (in float,
// the square of 1e20 overflows and that of 1e-30 vanishes). The one place this is computed, so that
// a camera written out by `vkray view` (position and look_at) reads back to the same bits.
glm::vec3 unit_direction(glm::vec3 d);

struct SampleStrata {
  uint32_t x = 1, y = 1;  // x * y >= spp, x = ceil(sqrt(spp)), y = ceil(spp / x)
  float inv_x = 1.0f, inv_y = 1.0f;
};

SampleStrata sample_strata(uint32_t samples_per_pixel);

}  // namespace vkray
