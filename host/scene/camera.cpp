#include "scene/camera.h"

#include <cmath>

namespace vkray {

CameraBasis camera_basis(const Camera& camera, uint32_t image_height) {
  CameraBasis basis;
  basis.origin = camera.position;
  basis.forward = camera.forward;
  basis.right = glm::normalize(glm::cross(camera.forward, camera.up));
  basis.up = glm::cross(basis.right, basis.forward);
  basis.focal_px = camera.focal_length * static_cast<float>(image_height);
  return basis;
}

glm::vec3 unit_direction(glm::vec3 d) {
  const float length = glm::length(d);
  return length > 0.0f && std::isfinite(length) ? d / length : glm::vec3(glm::normalize(glm::dvec3(d)));
}

SampleStrata sample_strata(uint32_t samples_per_pixel) {
  SampleStrata s;
  // Integer arithmetic only: a float sqrt could round 16 up to 4.0000005 and ceil it to 5.
  while (s.x * s.x < samples_per_pixel) ++s.x;
  s.y = (samples_per_pixel + s.x - 1) / s.x;
  s.inv_x = 1.0f / static_cast<float>(s.x);
  s.inv_y = 1.0f / static_cast<float>(s.y);
  return s;
}

}  // namespace vkray
