// The renderer's ray-triangle and ray-sphere routines and triangle normals (shaders/intersect.glsl), run on the device.
#include <cmath>
#include <cstddef>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "shaders/intersect_case.h"
#include "support/compute_kernel.h"
#include "support/gpu_fixture.h"

namespace vkray::test {
namespace {

using Case = gpu::IntersectCase;
static_assert(sizeof(Case) == 96 && offsetof(Case, dir) == 16 && offsetof(Case, a) == 32 && offsetof(Case, b) == 48 &&
              offsetof(Case, c) == 64 && offsetof(Case, range) == 80);

constexpr float kFar = 1e30f;

Case triangle(glm::vec3 o, glm::vec3 d, glm::vec3 v0, glm::vec3 v1, glm::vec3 v2, float t_min = 1e-4f, float t_max = kFar) {
  return {glm::vec4(o, 0), glm::vec4(glm::normalize(d), 0), glm::vec4(v0, 0), glm::vec4(v1, 0), glm::vec4(v2, 0),
          glm::vec4(t_min, t_max, 0, 0)};
}
Case sphere(glm::vec3 o, glm::vec3 d, glm::vec3 center, float radius, float t_min = 1e-4f, float t_max = kFar) {
  return {glm::vec4(o, 0), glm::vec4(glm::normalize(d), 0), glm::vec4(center, radius), {}, {}, glm::vec4(t_min, t_max, 1, 0)};
}

// The normal of the triangle v0 v1 v2 against the expected unit normal n: the kernel returns their dot product.
Case normal(glm::vec3 v0, glm::vec3 v1, glm::vec3 v2, glm::vec3 n) {
  return {{}, glm::vec4(n, 0), glm::vec4(v0, 0), glm::vec4(v1, 0), glm::vec4(v2, 0), glm::vec4(0, 0, 2, 0)};
}

class IntersectTest : public GpuTest {
 protected:
  std::vector<float> run(const std::vector<Case>& cases) {
    return run_kernel(session().context(), std::filesystem::path(VKRAY_TEST_SHADER_DIR) / "intersect_test.comp", cases.data(),
                      cases.size() * sizeof(Case), uint32_t(cases.size()), 1);
  }
  float run_one(const Case& c) { return run({c})[0]; }
};

// A unit right triangle in the z = 2 plane.
const glm::vec3 A(0, 0, 2), B(1, 0, 2), C(0, 1, 2);

TEST_F(IntersectTest, TriangleHitInsideGivesDistance) {
  EXPECT_NEAR(run_one(triangle({0.25f, 0.25f, 0}, {0, 0, 1}, A, B, C)), 2.0f, 1e-6f);
}

TEST_F(IntersectTest, TriangleIsTwoSided) {
  EXPECT_NEAR(run_one(triangle({0.25f, 0.25f, 5}, {0, 0, -1}, A, B, C)), 3.0f, 1e-6f);
  EXPECT_NEAR(run_one(triangle({0.25f, 0.25f, 0}, {0, 0, 1}, A, C, B)), 2.0f, 1e-6f);  // other winding
}

TEST_F(IntersectTest, TriangleMissOutside) {
  EXPECT_LT(run_one(triangle({0.6f, 0.6f, 0}, {0, 0, 1}, A, B, C)), 0.0f);  // beyond the hypotenuse
  EXPECT_LT(run_one(triangle({-0.1f, 0.5f, 0}, {0, 0, 1}, A, B, C)), 0.0f);
}

TEST_F(IntersectTest, TriangleBehindOriginIsNotHit) {
  EXPECT_LT(run_one(triangle({0.25f, 0.25f, 3}, {0, 0, 1}, A, B, C)), 0.0f);
}

TEST_F(IntersectTest, TriangleRespectsTRange) {
  EXPECT_LT(run_one(triangle({0.25f, 0.25f, 0}, {0, 0, 1}, A, B, C, 1e-4f, 1.5f)), 0.0f);
  EXPECT_LT(run_one(triangle({0.25f, 0.25f, 0}, {0, 0, 1}, A, B, C, 2.5f, kFar)), 0.0f);
}

TEST_F(IntersectTest, TriangleRayInItsPlaneIsNotHit) {
  // Exactly grazing: the ray runs inside the triangle's plane, across the triangle.
  EXPECT_LT(run_one(triangle({-1, 0.25f, 2}, {1, 0, 0}, A, B, C)), 0.0f);
}

TEST_F(IntersectTest, TriangleShallowGrazingRayHitsAtTheRightDistance) {
  // 1 milliradian above the plane; it crosses z = 2 at x = 0.25 after travelling ~1.25 units.
  const float angle = 1e-3f;
  const glm::vec3 d(std::cos(angle), 0, std::sin(angle));
  const float travel = 1.25f;
  const glm::vec3 o = glm::vec3(0.25f, 0.25f, 2) - travel * d;
  EXPECT_NEAR(run_one(triangle(o, d, A, B, C)), travel, 1e-3f);
}

TEST_F(IntersectTest, DegenerateTrianglesAreNeverHit) {
  const std::vector<float> t = run({
      triangle({0.5f, 0, 0}, {0, 0, 1}, A, B, {2, 0, 2}),            // collinear vertices
      triangle({0, 0, 0}, {0, 0, 1}, A, A, A),                       // a point
      triangle({0.25f, 0.25f, 0}, {0, 0, 1}, A, B, B),               // a segment
  });
  for (float v : t) EXPECT_LT(v, 0.0f);
}

TEST_F(IntersectTest, SharedEdgeHasNoCrack) {
  // A quad split along its diagonal; rays sweep across the diagonal x + y = 1 at many offsets:
  // every one must hit at least one of the two triangles.
  const glm::vec3 D(1, 1, 2);
  std::vector<Case> cases;
  const int n = 512;
  for (int i = 0; i < n; ++i) {
    const float s = (float(i) + 0.5f) / n;
    const glm::vec3 on_diagonal(s, 1 - s, 2);
    const glm::vec3 o(0.37f, 0.61f, -1.3f);  // off-axis origin so the rays are not axis-aligned
    cases.push_back(triangle(o, on_diagonal - o, B, C, A));
    cases.push_back(triangle(o, on_diagonal - o, B, D, C));
  }
  const std::vector<float> t = run(cases);
  int cracks = 0;
  for (int i = 0; i < n; ++i) cracks += (t[2 * i] < 0 && t[2 * i + 1] < 0);
  EXPECT_EQ(cracks, 0);
}

TEST_F(IntersectTest, HitBarycentricsKeepTheirPrecisionOnASliver) {
  // A triangle 100 long and 1 wide (its sharpest angle 0.57 degrees), hit at (60, 0.1): b1 to float
  // precision of the coordinates from the test's own edge functions, where solving it from the hit
  // point loses digits as 1 / sin^2 of that angle (1.2e-4 off here: a quarter of a texel of a
  // 2048-texel texture).
  const glm::dvec3 v0(0, 0, 2), v1(100, 0.5, 2), v2(100, -0.5, 2), p(60, 0.1, 2);
  // p = v0 + b1 (v1 - v0) + b2 (v2 - v0): x = 100 (b1 + b2), y = 0.5 (b1 - b2).
  const double exact = (p.x / 100 + p.y / 0.5) / 2;
  Case hit = triangle({60, 0.1f, 0}, {0, 0, 1}, v0, v1, v2);
  hit.range.z = 3;
  EXPECT_NEAR(run_one(hit), exact, 2e-7);
}

TEST_F(IntersectTest, TriangleNormalsAreUnitAtEveryScale) {
  // A tilted triangle, so that every component of its cross product is nonzero. At 6e-10 its squared
  // cross product is near the smallest normal float (a device that flushes subnormals normalizes by
  // too short a length); at 1e-12 it underflows to 0 and at 1e13 it overflows, on any device.
  const glm::vec3 v0(0.3f, -0.2f, 0.1f), v1(1.1f, 0.4f, -0.5f), v2(-0.4f, 0.9f, 0.7f);
  const glm::vec3 n = glm::normalize(glm::cross(glm::dvec3(v1 - v0), glm::dvec3(v2 - v0)));
  for (const float scale : {1.0f, 6e-10f, 1e-12f, 1e-15f, 1e13f, 1e17f}) {
    const glm::vec3 offset(scale * 2.0f, -scale, scale * 0.5f);
    const float agreement = run_one(normal(v0 * scale + offset, v1 * scale + offset, v2 * scale + offset, n));
    EXPECT_NEAR(agreement, 1.0f, 1e-5f) << "triangle scaled by " << scale;
  }
}

TEST_F(IntersectTest, SphereFromOutsideHitsNearSide) {
  EXPECT_NEAR(run_one(sphere({0, 0, 0}, {0, 0, 1}, {0, 0, 5}, 1)), 4.0f, 1e-5f);
}

TEST_F(IntersectTest, SphereFromInsideHitsFarSide) {
  EXPECT_NEAR(run_one(sphere({0, 0, 5}, {0, 0, 1}, {0, 0, 5}, 1)), 1.0f, 1e-5f);
  EXPECT_NEAR(run_one(sphere({0, 0, 4.5f}, {0, 0, -1}, {0, 0, 5}, 1)), 0.5f, 1e-5f);
}

TEST_F(IntersectTest, SphereBehindOriginIsNotHit) {
  EXPECT_LT(run_one(sphere({0, 0, 0}, {0, 0, -1}, {0, 0, 5}, 1)), 0.0f);
}

TEST_F(IntersectTest, SphereMissAndTangent) {
  EXPECT_LT(run_one(sphere({1.01f, 0, 0}, {0, 0, 1}, {0, 0, 5}, 1)), 0.0f);
  // Grazing: a ray passing at distance 0.9999 from the centre hits near t = 5.
  EXPECT_NEAR(run_one(sphere({0.9999f, 0, 0}, {0, 0, 1}, {0, 0, 5}, 1)), 5.0f - std::sqrt(1.0f - 0.9999f * 0.9999f), 2e-3f);
}

TEST_F(IntersectTest, SmallFarSphereKeepsPrecision) {
  // A 1e-3 sphere 1e3 away: the naive b^2 - c discriminant loses every digit here.
  EXPECT_NEAR(run_one(sphere({0, 0, 0}, {0, 0, 1}, {0, 0, 1000}, 1e-3f)), 1000.0f - 1e-3f, 1e-3f);
  EXPECT_LT(run_one(sphere({0, 2e-3f, 0}, {0, 0, 1}, {0, 0, 1000}, 1e-3f)), 0.0f);
}

TEST_F(IntersectTest, SphereRespectsTRange) {
  // With t_min past the near root, the far root counts.
  EXPECT_NEAR(run_one(sphere({0, 0, 0}, {0, 0, 1}, {0, 0, 5}, 1, 4.5f)), 6.0f, 1e-5f);
  EXPECT_LT(run_one(sphere({0, 0, 0}, {0, 0, 1}, {0, 0, 5}, 1, 1e-4f, 3.9f)), 0.0f);
}

}  // namespace
}  // namespace vkray::test
