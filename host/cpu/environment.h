// The CPU reference's environment map (Scene::environment): its radiance along a direction, and
// directions drawn in proportion to its luminance times sin(theta), with the same two numbers the
// shader draws (shaders/environment.glsl), from a distribution of its own, built in double.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace vkray::cpu {

using glm::dvec3;

class EnvironmentLight {
 public:
  explicit EnvironmentLight(const Environment& environment);

  // Whether the map sends any light (a black one is the black background).
  bool lights() const { return total_ > 0; }

  struct Lookup {
    dvec3 radiance{0.0};
    double pdf = 0;  // per unit solid angle, of sample() drawing that direction
  };
  // `dir`: unit, in the world.
  Lookup lookup(const dvec3& dir) const;

  struct Sample {
    dvec3 dir{0.0};  // unit, in the world
    dvec3 radiance{0.0};
    double pdf = 0;  // per unit solid angle; 0: none drawn (a pole)
  };
  // u_row picks the row, u_column the texel in it; what is left of each, the point in the texel.
  Sample sample(double u_row, double u_column) const;

 private:
  const Image& map_;
  glm::dmat3 to_world_, to_map_;
  uint32_t width_, height_;
  std::vector<double> rows_;     // height + 1 cumulative shares of the rows, from 0 to 1
  std::vector<double> columns_;  // per row, width + 1 cumulative shares of its texels, from 0 to 1
  std::vector<double> weight_;   // each texel's: luminance times sin(theta) at its row's centre
  double total_ = 0;

  // The texel's radiance and density per unit solid angle at polar sine `sin_theta`.
  Lookup texel(uint32_t x, uint32_t y, double sin_theta) const;
};

}  // namespace vkray::cpu
