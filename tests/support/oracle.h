// An independent implementation of the scene and shading contract, in double precision, written
// the plain way: ray-triangle by Cramer's rule on the 3x3 system, ray-sphere by the textbook
// quadratic. It shares only the scene loader with vkray. Tests compare the renderer with it at
// pixel centres that are "stable" (rays nudged by a fraction of a pixel see the same primitive and
// the same lights), where the two must agree to float precision.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene.h"

namespace vkray::test {

struct OracleSample {
  glm::dvec3 radiance{0.0};
  int primitive = -1;             // triangle index, then spheres; -1 for a miss
  std::vector<bool> lit_by;       // per light: contributes (visible and facing)
  bool operator==(const OracleSample& o) const { return primitive == o.primitive && lit_by == o.lit_by; }
};

class Oracle {
 public:
  Oracle(const Scene& scene, uint32_t width, uint32_t height);

  // The sample through image-plane position (px, py): pixel (i, j)'s centre is (i + 0.5, j + 0.5).
  OracleSample trace(double px, double py) const;

  // Whether the pixel centre's sample matches samples nudged by +-0.02 pixel in x and y.
  bool stable(uint32_t i, uint32_t j) const;

 private:
  struct Hit {
    double t;
    int primitive;
  };
  Hit closest(glm::dvec3 o, glm::dvec3 d, double t_min, double t_max) const;

  const Scene& scene_;
  uint32_t width_, height_;
  glm::dvec3 origin_, right_, up_, forward_;
  double focal_px_;
  double epsilon_;
};

}  // namespace vkray::test
