// vkray's library API, the one every face uses (the command line, and later the Python module and
// the farm driver): a session opens a device and compiles the shaders once, uploads scenes, and
// renders them with options, returning images. It owns the device, the pipelines and the
// validation log, checks the log after every step, and keeps the timeout policy (gpu/renderer.h).
#pragma once

#include <atomic>
#include <filesystem>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "gpu/device_info.h"
#include "session/options.h"
#include "session/progressive.h"

namespace vkray {
namespace gpu {
class Context;
class SceneBuffers;
class Renderer;
class TracePipeline;
class ValidationLog;
}  // namespace gpu

// A scene on the device (its BVH built, its buffers uploaded), ready for any number of renders, as
// the faces hold it: a handle to the session's gpu::SceneBuffers that copies cheaply, owns its Scene
// and keeps the device alive, so it may be held as long as the caller likes (but released before
// Session::close()).
class DeviceScene {
 public:
  const Scene& scene() const;
  double upload_seconds() const;  // BVH build included, also when built beforehand
  double bvh_seconds() const;
  double environment_seconds() const;  // of upload_seconds: the environment map's distribution, built
  // Made by Session::upload_changes from a scene with the same geometry, whose BVH and primitive
  // buffers it shares.
  bool shares_geometry() const;

 private:
  friend class Session;
  DeviceScene(std::shared_ptr<const gpu::SceneBuffers> buffers, std::shared_ptr<const SceneBvh> bvh)
      : buffers_(std::move(buffers)), bvh_(std::move(bvh)) {}
  std::shared_ptr<const gpu::SceneBuffers> buffers_;
  // The tree on the device, as built: a band of a region is estimated with it instead of a tree built
  // again for each band (about a second for two million triangles), at the cost of keeping its nodes in
  // host memory as long as the handle (less than the scene's own triangles take).
  std::shared_ptr<const SceneBvh> bvh_;
};

class Session {
 public:
  // Opens the device. Throws DeviceError (no such device, the validation layer missing). The shaders
  // are compiled by compile_shaders(), or by the first prepare() or render().
  explicit Session(const SessionOptions& options);
  // Releases the device without checking the validation log (close() checks it).
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const std::string& device_name() const;
  const std::string& driver_name() const;
  std::string device_description() const;  // "name (driver)"
  const gpu::DeviceInfo& device_info() const;  // as `vkray devices` lists it: index, type, driver, Vulkan version

  // ---- Shaders ----------------------------------------------------------------------------------
  struct ShaderCompile {
    double seconds;
    // false: the SPIR-V is the running one's, and the pipelines compiled from it stay (those with a
    // scene compiled in are compiled again when next needed, from the files as they are now).
    bool spirv_changed;
  };
  // Compiles shader_dir/trace.comp, again when it was compiled before (vkray watch). Throws
  // ShaderError, and the shaders in use (if any) stay in use.
  ShaderCompile compile_shaders();
  bool has_shaders() const;
  // trace.comp and every file it included, as last compiled; just trace.comp before that.
  std::vector<std::filesystem::path> shader_sources() const;

  // ---- Scenes -----------------------------------------------------------------------------------
  // Builds the scene's BVH (or takes `bvh`, built for this scene) and uploads it. Throws
  // TimeoutError at once while a tile that timed out still runs on the device.
  DeviceScene upload(std::shared_ptr<const Scene> scene, std::shared_ptr<const SceneBvh> bvh = nullptr);
  // `scene`, an edit of `previous` (uploaded by this session): when their geometry is the same
  // (same_geometry: a camera, lights, materials, the image or the integrator changed), it shares
  // `previous`'s BVH and primitive buffers and uploads only the lighting; otherwise upload(scene).
  DeviceScene upload_changes(const DeviceScene& previous, std::shared_ptr<const Scene> scene);

  // ---- Rendering (of a scene uploaded by this session; another's is a UsageError) ----------------
  // Whether a render of `scene` with `options` traces code compiled from the scene, not the BVH.
  bool compiles_scene_in(const DeviceScene& scene, const RenderOptions& options) const;
  // Compiles now the pipeline a render of `scene` with `options` needs, so that a caller can time
  // compiling apart from tracing; returns the seconds it took. Throws ShaderError.
  double prepare(const DeviceScene& scene, const RenderOptions& options);
  // Throws Cancelled (on the process-wide interrupt request, base/interrupt.h: Ctrl-C stops every
  // render in the process, and a face that goes on afterwards clears it), TimeoutError (a tile
  // outlived options.tile_timeout), DeviceLostError, DeviceError, ShaderError, UsageError.
  RenderResult render(const DeviceScene& scene, const RenderOptions& options);
  // A render that the caller advances step by step (session/progressive.h), for a viewer: its image,
  // once done, is render()'s for the same scene and options. `rate_hint`: pixels x samples a second
  // measured before (ProgressiveRender::rate()), to size the first step; 0: a band of rows. With
  // options.aovs it accumulates the first-hit passes too. Not with a region (UsageError). Release it
  // before close().
  std::unique_ptr<ProgressiveRender> start_progressive(const DeviceScene& scene, const RenderOptions& options,
                                                       double rate_hint = 0);

  // ---- Ending -----------------------------------------------------------------------------------
  // Releases the device; afterwards every call but close() throws UsageError. Throws DeviceError
  // when the validation layer reported anything, its report of objects left alive at teardown
  // included. Every DeviceScene must be released first (InternalError otherwise).
  void close();

  // The device itself, for tests that run kernels of their own on it, and for a viewer's swapchain
  // (SessionOptions::surface) on its queue.
  const gpu::Context& context() const { return device(); }

 private:
  // The device; UsageError once the session is closed.
  const gpu::Context& device() const;
  // `scene`'s buffers, when this session uploaded it.
  const gpu::SceneBuffers& own(const DeviceScene& scene) const;
  // Throws DeviceError when the validation layer has reported anything since the last check.
  void check_validation(const char* during);

  std::filesystem::path shader_dir_;
  std::optional<std::filesystem::path> shader_cache_;  // compiled shaders kept between runs (gpu/shader_cache.h)
  std::shared_ptr<gpu::ValidationLog> validation_log_;  // outlives the device, whose teardown may report
  size_t validation_seen_ = 0;
  std::shared_ptr<const gpu::Context> ctx_;
  struct Shaders;
  std::unique_ptr<Shaders> shaders_;  // the pipeline cache and the current TracePipeline
  std::unique_ptr<gpu::Renderer> renderer_;
};

// Whether a render that timed out left work running on a device, work the process will not wait
// for: it must then end with std::_Exit, since exit handlers (the driver's own) could wait on it
// without end.
bool device_work_left_running();

// Every Vulkan device the loader reports, in loader order (the index `SessionOptions::device` takes).
using gpu::DeviceInfo;
using gpu::list_devices;

// A scene's BVH built on other threads while a face opens the device and compiles the shaders, then
// handed to Session::upload(). Left unfetched (an error elsewhere), it stops the build and waits
// only the milliseconds that takes, so that the error is reported at once.
class BackgroundBvh {
 public:
  explicit BackgroundBvh(std::shared_ptr<const Scene> scene);
  ~BackgroundBvh();
  BackgroundBvh(const BackgroundBvh&) = delete;
  BackgroundBvh& operator=(const BackgroundBvh&) = delete;

  // Waits for the tree. Throws what the build threw (LimitError, Cancelled).
  SceneBvh get();

 private:
  std::shared_ptr<std::atomic<bool>> stop_;  // shared with the building thread, which may outlive a moved-from future
  std::future<SceneBvh> build_;
};

}  // namespace vkray
