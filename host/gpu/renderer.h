// The GPU path: the compute pipeline built from trace.comp's SPIR-V, and a render that uploads a
// scene, dispatches the image tile by tile and reads the radiance back.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "errors.h"
#include "gpu/context.h"
#include "image.h"
#include "scene.h"

namespace vkray {
struct Bvh;
}

namespace vkray::gpu {

// Descriptor set layout, pipeline layout and pipeline for shaders/trace.comp's interface.
class TracePipeline {
 public:
  // `cache` (optional) makes re-creating a pipeline from SPIR-V seen before in this process cheap.
  TracePipeline(const Context& ctx, const std::vector<uint32_t>& spirv, const vk::raii::PipelineCache* cache = nullptr);

  const vk::raii::DescriptorSetLayout& set_layout() const { return set_layout_; }
  const vk::raii::PipelineLayout& layout() const { return layout_; }
  const vk::raii::Pipeline& pipeline() const { return pipeline_; }

 private:
  vk::raii::DescriptorSetLayout set_layout_{nullptr};
  vk::raii::PipelineLayout layout_{nullptr};
  vk::raii::Pipeline pipeline_{nullptr};
};

// A scene on the device: its BVH built and its buffers uploaded, ready for any number of renders.
class GpuScene {
 public:
  // `bvh`: one already built for this scene; null builds one.
  GpuScene(const Context& ctx, const Scene& scene, const Bvh* bvh = nullptr);
  ~GpuScene();
  GpuScene(GpuScene&&) noexcept;

  const Scene& scene() const { return *scene_; }
  double bvh_seconds() const { return bvh_seconds_; }
  double upload_seconds() const { return upload_seconds_; }  // BVH build included
  uint32_t primitive_count() const { return primitive_count_; }

 private:
  friend Image render(Context&, const TracePipeline&, const GpuScene&, const struct ImageSettings&,
                      const struct RenderOptions&, struct RenderStats*);
  struct Buffers;
  const Scene* scene_;
  std::unique_ptr<Buffers> buffers_;
  uint32_t primitive_count_ = 0;
  double bvh_seconds_ = 0, upload_seconds_ = 0;
};

struct RenderStats {
  double bvh_seconds = 0;  // building the BVH (part of upload_seconds)
  double upload_seconds = 0;
  double trace_seconds = 0;
  double readback_seconds = 0;
  uint64_t rays = 0;  // camera rays + shadow rays
  uint32_t tiles = 0;
};

struct RenderOptions {
  // Longest a single tile may run before the render fails with a device error.
  std::chrono::milliseconds tile_timeout{60000};
  // Tile side in pixels; 0 chooses it from the scene (see tile_side()).
  uint32_t tile_side = 0;
  // Called after each tile with (tiles done, tiles in all).
  std::function<void(uint32_t, uint32_t)> progress;
  // Asked between tiles; when it returns true the render stops and throws Cancelled.
  std::function<bool()> cancel;
  // false: no shadow rays, every light counts as visible (benchmarks of camera rays alone).
  bool shadows = true;
};

// A render stopped by RenderOptions::cancel; no work is left in flight.
struct Cancelled {};

// A tile did not finish within RenderOptions::tile_timeout; work may still be in flight.
struct TimeoutError : DeviceError {
  using DeviceError::DeviceError;
};

// Renders a scene already on the device at `image` resolution and sample count. Throws
// DeviceError (and vk::SystemError from failing Vulkan calls).
Image render(Context& ctx, const TracePipeline& pipeline, const GpuScene& scene, const ImageSettings& image,
             const RenderOptions& options = {}, RenderStats* stats = nullptr);

// The same for a scene not yet on the device: uploads it, renders, frees it (stats include the upload).
Image render(Context& ctx, const TracePipeline& pipeline, const Scene& scene, const ImageSettings& image,
             const RenderOptions& options = {}, RenderStats* stats = nullptr);

// Tile side in pixels (a multiple of the workgroup size) so that one submission stays near a fixed
// budget of ray-primitive tests whatever the scene size and sample count.
uint32_t tile_side(const Scene& scene, const ImageSettings& image);

}  // namespace vkray::gpu
