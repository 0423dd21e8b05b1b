// Parity: a scene rendered on the session's device and with the CPU reference, both traversing the
// same BVH, and the two images and their first-hit passes compared against the tolerance
// (compare/parity_metrics.h).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "compare/parity_metrics.h"
#include "session/options.h"
#include "session/session.h"

namespace vkray {

struct ParityResult {
  ImageSettings image;   // what both rendered
  RenderResult gpu;
  RenderResult cpu;      // the CPU reference
  // Per pixel, what the reference's samples saw (cpu/reference.h): neighbours that differ mark an edge.
  std::vector<uint64_t> signatures;
  ParityTolerance tolerance;
  ParityMetrics metrics;
};

// The tolerance a render of `scene` is judged by: the stochastic one when it makes random decisions.
ParityTolerance parity_tolerance(const Scene& scene);

ParityResult compare_with_reference(Session& session, std::shared_ptr<const Scene> scene, const RenderOptions& options);

// The comparison alone, of a GPU render and a reference rendered with `signatures`, both of `image`;
// their first-hit passes too when both have them (lengths compared against `scene_extent`).
ParityResult judge_parity(const ImageSettings& image, RenderResult gpu, RenderResult cpu, std::vector<uint64_t> signatures,
                          const ParityTolerance& tolerance, double scene_extent = 1.0);

}  // namespace vkray
