// The area lights: every primitive whose material emits, and the table both renderers pick one from
// (shaders/shared/scene_layout.h, "Emissive primitives"), so that they pick the same light for the
// same random number. The table is scene set-up, like the camera basis; how a point on the light
// is chosen and weighed is each renderer's own code.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace vkray {

struct EmitterTable {
  struct Entry {
    float probability = 1.0f;  // of keeping this entry rather than its alias
    uint32_t alias = 0;
    uint32_t primitive = 0;    // in the scene's numbering (PrimitiveNumbering)
  };
  std::vector<Entry> entries;  // empty when nothing emits
  double total_weight = 0;     // the sum of area * luminance(emission) over the entries
  // For each of the scene's materials, the density per unit area with which light sampling picks a
  // point of one of its emitters: luminance(emission) / total_weight (0 for a material with none).
  std::vector<double> density;
};

// The alias table over the emissive primitives, each weighted by its power. Primitives whose
// weight is 0 (an emission of zero luminance, an area that underflows) are left out: they would
// never be picked.
EmitterTable build_emitter_table(const Scene& scene);

// The area of primitive p (the scene's numbering) where the scene places it, in double.
double primitive_area(const Scene& scene, const PrimitiveNumbering& numbering, uint64_t p);

}  // namespace vkray
