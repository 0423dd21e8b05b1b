#include "scene/transform.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace vkray {

glm::mat4 compose_transform(glm::vec3 translate, glm::vec3 rotate_degrees, glm::vec3 scale) {
  const glm::mat4 identity(1.0f);
  return glm::translate(identity, translate) *
         glm::rotate(identity, glm::radians(rotate_degrees.z), glm::vec3(0, 0, 1)) *
         glm::rotate(identity, glm::radians(rotate_degrees.y), glm::vec3(0, 1, 0)) *
         glm::rotate(identity, glm::radians(rotate_degrees.x), glm::vec3(1, 0, 0)) *
         glm::scale(identity, scale);
}

glm::mat4 matrix_from_row_major(const float (&m)[16]) {
  glm::mat4 result;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) result[col][row] = m[row * 4 + col];
  return result;
}

glm::vec3 transform_point(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }

std::optional<float> uniform_scale_of(const glm::mat4& m) {
  // In double: squared lengths of float columns neither overflow nor underflow there (a scale of
  // 1e-30 or 1e30 is still a uniform scale; whether its result is too large is the scene's check).
  const glm::dmat3 linear{glm::mat3(m)};
  const double s = glm::length(linear[0]);
  if (!(s > 0.0)) return std::nullopt;
  // Columns of s * R are orthogonal and all of length s. Tolerance: a few float ulps of rounding in
  // matrices written with 6-7 significant digits.
  constexpr double kTolerance = 1e-5;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(glm::length(linear[i]) - s) > kTolerance * s) return std::nullopt;
    for (int j = i + 1; j < 3; ++j)
      if (std::abs(glm::dot(linear[i], linear[j])) > kTolerance * s * s) return std::nullopt;
  }
  return static_cast<float>(s);
}

}  // namespace vkray
