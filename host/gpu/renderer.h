// The GPU path: the compute pipeline built from trace.comp's SPIR-V, and a render that uploads a
// scene, dispatches the image tile by tile and reads the radiance back.
#pragma once

#include <chrono>
#include <compare>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "base/errors.h"
#include "gpu/context.h"
#include "gpu/descriptors.h"
#include "gpu/shader_compiler.h"
#include "packing/inline_scene.h"
#include "image/image.h"
#include "scene/scene.h"

namespace vkray {
struct Bvh;
}

namespace vkray::gpu {

// What a scene needs of the shader: specialization constants (shared/types.h), so that the
// pipeline for a scene has no code for what the scene lacks (on llvmpipe code behind an if costs
// every lane even when no lane takes it), and the scene's own code when it is compiled in.
struct ShaderVariant {
  bool spheres = true;       // VKRAY_SPEC_SPHERES
  bool shadows = true;       // VKRAY_SPEC_SHADOWS (RenderOptions::shadows)
  std::string inline_scene;  // served as shaders/inline_scene.glsl; empty: that file, and the BVH is walked

  auto operator<=>(const ShaderVariant&) const = default;
};

class GpuScene;

// Whether a render of `scene` at `image` uses the code compiled from it, under `policy`.
bool use_inline_scene(const GpuScene& scene, const ImageSettings& image, InlineScene policy);

ShaderVariant shader_variant(const GpuScene& scene, const ImageSettings& image, InlineScene policy,
                             bool shadows = true);

// Descriptor set layout, pipeline layout and the pipelines for shaders/trace.comp's interface, one
// per ShaderVariant, each compiled the first time a render needs it.
class TracePipeline {
 public:
  // `spirv`: shader_dir/trace.comp compiled as it is (compile_compute_shader); variants with a
  // scene compiled in are compiled from shader_dir when first needed. `cache` (optional; it must
  // outlive this) makes re-creating a pipeline from SPIR-V seen before in this process cheap.
  // Throws ShaderError when the shader declares its bindings otherwise than vkray binds them.
  TracePipeline(const Context& ctx, std::filesystem::path shader_dir, const CompiledShader& shader,
                const vk::raii::PipelineCache* cache = nullptr);
  ~TracePipeline();

  const DescriptorTable& descriptors() const { return descriptors_; }
  const vk::raii::PipelineLayout& layout() const { return layout_; }
  // The pipeline for `variant`, compiled now if not kept from before. Callers that time compilation
  // apart from tracing call this before rendering. Throws ShaderError when the shaders do not compile
  // with a scene's generated code (a shader folder whose traversal.glsl no longer fits the contract in
  // inline_scene.glsl). The few most recent variants with a scene compiled in are kept.
  std::shared_ptr<const vk::raii::Pipeline> pipeline(const ShaderVariant& variant) const;

 private:
  std::shared_ptr<const vk::raii::Pipeline> create(const ShaderVariant& variant) const;

  const vk::raii::Device* device_;
  const vk::raii::PipelineCache* cache_;
  std::filesystem::path shader_dir_;
  DescriptorTable descriptors_;
  vk::raii::PipelineLayout layout_{nullptr};
  vk::raii::ShaderModule module_{nullptr};
  mutable std::mutex mutex_;
  mutable std::map<ShaderVariant, std::shared_ptr<const vk::raii::Pipeline>> pipelines_;
  mutable std::deque<ShaderVariant> inline_order_;  // variants with a scene compiled in, oldest first
};

// A scene on the device: its BVH built and its buffers uploaded, ready for any number of renders.
class GpuScene {
 public:
  // `bvh`: one already built for this scene; null builds one.
  GpuScene(const Context& ctx, const Scene& scene, const Bvh* bvh = nullptr);
  ~GpuScene();
  GpuScene(GpuScene&&) noexcept;

  const Scene& scene() const { return *scene_; }
  // The code that compiles this scene into the shader (inline_scene_glsl); empty for a scene with
  // more than kMaxInlinePrimitives primitives, or none.
  const std::string& inline_scene() const { return inline_scene_; }
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
  std::string inline_scene_;
  double bvh_seconds_ = 0, upload_seconds_ = 0;
};

struct RenderStats {
  double bvh_seconds = 0;  // building the BVH (part of upload_seconds)
  double upload_seconds = 0;
  double trace_seconds = 0;
  double readback_seconds = 0;
  uint64_t rays = 0;  // camera rays + shadow rays
  uint32_t tiles = 0;
  bool inline_scene = false;  // traced by code compiled from the scene, not by walking the BVH
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
  InlineScene inline_scene = InlineScene::automatic;
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
