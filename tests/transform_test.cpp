#include <gtest/gtest.h>

#include "scene/transform.h"

namespace vkray {
namespace {

void expect_near(glm::vec3 a, glm::vec3 b) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-5f) << "component " << c;
}

TEST(TransformTest, RotationsAreRightHandedAndXComesFirst) {
  expect_near(transform_point(compose_transform({}, {90, 0, 0}, glm::vec3(1)), {0, 1, 0}), {0, 0, 1});
  expect_near(transform_point(compose_transform({}, {0, 90, 0}, glm::vec3(1)), {0, 0, 1}), {1, 0, 0});
  expect_near(transform_point(compose_transform({}, {0, 0, 90}, glm::vec3(1)), {1, 0, 0}), {0, 1, 0});
  // x first: (0, 1, 0) -Rx(90)-> (0, 0, 1) -Ry(90)-> (1, 0, 0). (y first would give (0, 0, 1).)
  expect_near(transform_point(compose_transform({}, {90, 90, 0}, glm::vec3(1)), {0, 1, 0}), {1, 0, 0});
}

TEST(TransformTest, ScaleBeforeTranslate) {
  expect_near(transform_point(compose_transform({1, 2, 3}, {}, {2, 3, 4}), {1, 1, 1}), {3, 5, 7});
}

TEST(TransformTest, RowMajorMatrix) {
  const float m[16] = {1, 0, 0, 5, 0, 1, 0, 6, 0, 0, 1, 7, 0, 0, 0, 1};
  expect_near(transform_point(matrix_from_row_major(m), {1, 1, 1}), {6, 7, 8});
}

TEST(TransformTest, UniformScaleDetection) {
  EXPECT_NEAR(*uniform_scale_of(compose_transform({4, 5, 6}, {10, 20, 30}, glm::vec3(2.5f))), 2.5f, 1e-5f);
  EXPECT_NEAR(*uniform_scale_of(compose_transform({}, {}, glm::vec3(-2))), 2.0f, 1e-6f);  // a mirror keeps the radius
  EXPECT_FALSE(uniform_scale_of(compose_transform({}, {0, 45, 0}, {1, 2, 1})).has_value());
}

}  // namespace
}  // namespace vkray
