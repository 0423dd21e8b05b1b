// One ray-primitive test case of tests/shaders/intersect_test.comp, written once for the kernel
// (GLSL) and for tests/intersect_test.cpp (C++, std430: six vec4s, 96 bytes).
#ifndef VKRAY_TEST_INTERSECT_CASE_H
#define VKRAY_TEST_INTERSECT_CASE_H

#include "shared/glsl_cpp.h"

VKRAY_SHARED_BEGIN

struct IntersectCase {
  vec4 origin;  // xyz
  vec4 dir;     // xyz, unit length
  vec4 a;       // triangle: v0; sphere: center (xyz) and radius (w)
  vec4 b;       // triangle: v1
  vec4 c;       // triangle: v2
  vec4 range;   // t_min, t_max, kind (0 triangle, 1 sphere, 2 the triangle's normal against dir, 3 and 4 the
                //   barycentric b1 of the hit: from the test's edge functions, and solved from the hit point)
};

VKRAY_SHARED_END

#endif  // VKRAY_TEST_INTERSECT_CASE_H
