// The GPU path's render: the image traced tile by tile, one submission and one bounded wait per
// tile (lavapipe has no GPU watchdog), and the radiance read back. What happens to a tile that
// outlives its timeout is decided here, once.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "gpu/context.h"
#include "gpu/scene_buffers.h"
#include "gpu/pipeline.h"
#include "image/aovs.h"
#include "image/image.h"
#include "image/region.h"
#include "scene/scene.h"
#include "shared/first_hit_layout.h"
#include "shared/types.h"

namespace vkray::gpu {

struct TraceRequest {
  ImageSettings image;  // the resolution and sample count rendered
  // Only these pixels (empty: the whole image), each the same as in a render of the whole image.
  PixelRegion region;
  ShaderVariant variant;
  // Longest one tile may run before the render fails with TimeoutError.
  std::chrono::milliseconds tile_timeout{60000};
  // Square tiles of this side in pixels; 0: submissions sized by the time they take (gpu/tiling.h).
  uint32_t tile_side = 0;
  // Called after each tile with (pixels done, pixels in all).
  std::function<void(uint32_t, uint32_t)> progress;
};

struct TraceStats {
  double upload_seconds = 0;  // the frame's uniforms, output buffer and descriptors
  double trace_seconds = 0;
  double readback_seconds = 0;
  uint64_t rays = 0;  // camera rays + shadow rays
  uint32_t tiles = 0;
};

// A pixel's first-hit sums as the shader left them.
FirstHitSums first_hit_sums(const FirstHitTexels& texels);

// The most samples of a pixel one dispatch traces for `scene` (llvmpipe's loop limit; renderer.cpp).
uint32_t samples_in_one_dispatch(const Scene& scene, const ShaderVariant& variant);

// Records the dispatches of samples [sample_begin, sample_end) of `tile`'s pixels, at most
// samples_per_dispatch a dispatch, each continuing the last one's sums, then the barrier that makes
// the sums visible to the host. The pipeline and descriptors are bound.
void record_sample_dispatches(const vk::raii::CommandBuffer& cb, vk::PipelineLayout layout, TileConstants tile,
                              uint32_t sample_begin, uint32_t sample_end, uint32_t samples_per_dispatch);

class Renderer {
 public:
  explicit Renderer(std::shared_ptr<const Context> ctx);
  // Work of a timed-out render that is still running keeps what it uses: it is left to the process,
  // never destroyed under the device (Context::abandon_work()).
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders `scene` with `pipeline`'s variant for the request (the region's pixels); with
  // request.variant.aovs, also the first-hit passes, into `aovs`. Throws TimeoutError when a tile
  // outlives request.tile_timeout (its work may go on: what it uses is kept until it finishes, and
  // the next render first waits up to its own tile timeout for it), Cancelled on an interrupt
  // request (a tile still running is kept the same way), and DeviceError or vk::SystemError for
  // failed calls.
  Image render(std::shared_ptr<const TracePipeline> pipeline, std::shared_ptr<const SceneBuffers> scene,
               const TraceRequest& request, TraceStats* stats = nullptr, Aovs* aovs = nullptr);

  // Whether work of a timed-out render is still running, after waiting up to `wait` for it. What
  // finished work used is released.
  bool busy(std::chrono::milliseconds wait);
  // Waits up to `wait` for the tiles interrupted renders left running (a tile runs on after Ctrl-C
  // until its submission ends), then says, as busy(0) does, whether work is still running: that of
  // a render that timed out, or an interrupted tile past `wait`. Throws Cancelled on an interrupt
  // request while it waits.
  bool busy_after_interrupts(std::chrono::milliseconds wait);

 private:
  struct Frame;
  // Submits the region's tiles, each queued behind the one before, and reads each back into
  // `result` (and `aovs`, when not null) while the next one traces; adds the rays and the time spent
  // reading back to `stats`.
  void trace_tiles(Frame& frame, const TraceRequest& request, const PixelRegion& region, Image& result, Aovs* aovs,
                   TraceStats& stats);

  std::shared_ptr<const Context> ctx_;
  std::vector<std::unique_ptr<Frame>> abandoned_;  // frames whose last tile timed out
};

}  // namespace vkray::gpu
