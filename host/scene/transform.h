// Object transforms of the scene contract: M = T * Rz(az) * Ry(ay) * Rx(ax) * S (the lecture's
// R_xyz: x is applied first), or a full 4x4 matrix.
#pragma once

#include <optional>

#include <glm/glm.hpp>

namespace vkray {

// rotate_degrees = (ax, ay, az).
glm::mat4 compose_transform(glm::vec3 translate, glm::vec3 rotate_degrees, glm::vec3 scale);

// Row-major 16 numbers, as written in a scene file, to a GLM (column-major) matrix.
glm::mat4 matrix_from_row_major(const float (&m)[16]);

glm::vec3 transform_point(const glm::mat4& m, glm::vec3 p);

// The factor s if m's linear part is s times a rotation (what a sphere can take), else nothing.
std::optional<float> uniform_scale_of(const glm::mat4& m);

}  // namespace vkray
