// A render that goes on between calls: the image's running sums stay on the device, and each step
// adds samples to a band of rows, so that a window can show an image that improves frame after
// frame and still answer input between frames. The sums are those Renderer::render builds (the
// same dispatches' arithmetic, sample by sample in order), so that once every pixel has all
// ImageSettings::samples_per_pixel samples the image is, bit for bit, the one a render returns.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/pipeline.h"
#include "gpu/scene_buffers.h"
#include "image/aovs.h"
#include "image/image.h"
#include "shared/first_hit_layout.h"

namespace vkray::gpu {

// Samples [sample_begin, sample_end) of every pixel in rows [y0, y1); each pixel there must have
// exactly sample_begin samples so far.
struct AccumulationStep {
  uint32_t y0 = 0, y1 = 0;
  uint32_t sample_begin = 0, sample_end = 0;
  uint64_t pixel_samples(uint32_t width) const { return uint64_t(width) * (y1 - y0) * (sample_end - sample_begin); }
};

class Accumulator {
 public:
  // Throws DeviceError when the image's sums do not fit one storage buffer of the device.
  Accumulator(std::shared_ptr<const Context> ctx, std::shared_ptr<const TracePipeline> trace_pipeline,
              std::shared_ptr<const SceneBuffers> scene, const ImageSettings& image, const ShaderVariant& variant);
  // Waits (a bounded time) for a step still on the device; a step still running past it is left to
  // the process, as Renderer leaves a tile that timed out.
  ~Accumulator();
  Accumulator(const Accumulator&) = delete;
  Accumulator& operator=(const Accumulator&) = delete;

  // Traces the step and waits for it. Returns its device time in seconds (from submission to the
  // fence). Where the driver cut the shader's loops short (llvmpipe, renderer.cpp) the rows are put
  // back as they were and traced again with fewer samples a dispatch. Throws TimeoutError when a
  // submission outlives `timeout`, Cancelled, DeviceError.
  double trace(const AccumulationStep& step, std::chrono::milliseconds timeout);

  // The radiance sums of rows [y0, y1) into the same rows of `sums` (width x height), unscaled (as
  // Renderer::render returns them): each the sum of a pixel's samples so far, each over the whole
  // render's sample count.
  void read(uint32_t y0, uint32_t y1, Image& sums) const;
  // The first-hit passes of rows [y0, y1) into the same rows of `aovs` (width x height), each the
  // mean over the samples so far that hit something, as Renderer::render gives them. Only when made
  // with ShaderVariant::aovs.
  void read_aovs(uint32_t y0, uint32_t y1, Aovs& aovs) const;
  bool has_aovs() const { return aovs_; }
  // Camera and shadow rays traced so far.
  uint64_t rays() const { return rays_; }

  const ImageSettings& image() const { return image_; }

 private:
  // Records and submits the step's dispatches, then waits for them. Returns the device time.
  double submit_and_wait(const AccumulationStep& step, uint32_t samples_per_dispatch, std::chrono::milliseconds timeout);
  // Whether any pixel of rows [y0, y1) says its loops were cut short; adds their rays otherwise.
  bool rows_complete(uint32_t y0, uint32_t y1, uint64_t* rays) const;

  std::shared_ptr<const Context> ctx_;
  std::shared_ptr<const TracePipeline> trace_pipeline_;
  std::shared_ptr<const SceneBuffers> scene_;
  std::shared_ptr<const vk::raii::Pipeline> pipeline_;
  ImageSettings image_;
  uint32_t samples_per_dispatch_;
  Buffer uniforms_;
  Buffer output_;      // the sums: one vec4 per pixel, host-visible
  bool aovs_ = false;
  Buffer aov_output_;  // the first-hit sums, one FirstHitTexels per pixel (a placeholder without passes)
  std::optional<DescriptorSet> descriptors_;
  vk::raii::CommandPool command_pool_{nullptr};
  vk::raii::CommandBuffer command_buffer_{nullptr};
  vk::raii::Fence fence_{nullptr};
  bool in_flight_ = false;
  // The step's rows as they were, put back when its loops were cut short.
  std::vector<glm::vec4> saved_;
  std::vector<FirstHitTexels> saved_aovs_;
  uint64_t rays_ = 0;
};

}  // namespace vkray::gpu
