// The CPU reference renderer: an independent second implementation of the scene and shading
// contract, against which the GPU path is checked (vkray parity). It shares only the scene loader,
// the camera basis and the sample pattern with the GPU path; its intersection and shading code is
// its own, written the plain way the lecture writes it, in double precision.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <optional>

#include "image/aovs.h"
#include "image/image.h"
#include "image/region.h"
#include "scene/scene.h"

namespace vkray {
struct SceneBvh;
}

namespace vkray::cpu {

struct ReferenceOptions {
  unsigned threads = 0;  // 0: one per hardware thread. The image does not depend on it.
  bool use_bvh = true;   // false: test every primitive (slow; checks the traversal)
  const SceneBvh* bvh = nullptr;  // a BVH already built for this scene; null: build one
  bool shadows = true;   // false: no shadow rays, every light counts as visible (benchmarks)
  bool sample_environment = true;  // false: the environment map found by BSDF sampling alone (RenderOptions)
  bool aovs = false;     // also the first-hit passes (image/aovs.h)
  // Only these pixels of the image (empty: all of them); each pixel's samples are the same as in a
  // render of the whole image.
  PixelRegion region;
  std::function<void(uint32_t rows_done, uint32_t rows)> progress;  // called under a lock
  // On an interrupt request (base/interrupt.h) the threads stop and render_reference throws
  // Cancelled.
};

struct ReferenceResult {
  Image image;  // the region's pixels
  PixelRegion region;  // the pixels rendered, in the image's coordinates
  std::optional<Aovs> aovs;  // when ReferenceOptions::aovs asked for them
  // Per pixel, a hash of what each sample saw (the primitive hit and the lights that lit it). Two
  // neighbouring pixels with different signatures straddle a silhouette or shadow edge.
  std::vector<uint64_t> signatures;
  uint64_t rays = 0;  // camera rays + shadow rays
  std::vector<uint64_t> rays_per_row;  // the same for each row of the region, top first
  double seconds = 0;       // tracing, BVH build included
  double bvh_seconds = 0;   // building the BVH
};

ReferenceResult render_reference(const Scene& scene, const ImageSettings& image, const ReferenceOptions& options = {});

}  // namespace vkray::cpu
