// What a caller asks of a render, whichever face it comes from (the command line's flags map onto
// these in one place, host/cli/flags.cpp), and what a render reports back.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "base/errors.h"
#include "base/threads.h"
#include "gpu/surface_request.h"
#include "image/aovs.h"
#include "image/image.h"
#include "scene/scene.h"
#include "session/regions.h"

namespace vkray {

// ---- The numbers a caller gives ------------------------------------------------------------------
// One entry for each number a face takes (a flag of the command line, a keyword argument of the
// Python module), so that every face checks the same range and says the same thing; image_settings()
// checks RenderOptions against the same entries for any other caller of the library.
struct ArgumentLimit {
  std::string_view name;  // as Python spells it; the command line's flag is --name, with '-' for '_'
  uint32_t min, max;

  bool contains(int64_t value) const { return value >= int64_t(min) && value <= int64_t(max); }
  // "expected an integer from 1 to 16384, got 0", `got` as the caller wrote the value: what the
  // command line prints after the flag's name ("--width: ...").
  std::string expected(std::string_view got) const;
  // UsageError("width: " + expected(got)).
  UsageError error(std::string_view got) const;

  // A value given as text, read as the command line reads its integers: decimal digits only,
  // leading zeros read as decimal ("0100" is 100), a leading '-' out of range. What is wrong with it
  // in the words the command line prints after the flag's name ("expected a decimal integer, got
  // \"1_000\"", or expected()); empty when it is right.
  std::string problem(std::string_view text) const;
  // The value `text` names; UsageError("width: " + problem(text)) when problem() is not empty.
  uint32_t read(std::string_view text) const;
};

inline constexpr ArgumentLimit kWidthArgument{"width", 1, kMaxImageSide};
inline constexpr ArgumentLimit kHeightArgument{"height", 1, kMaxImageSide};
inline constexpr ArgumentLimit kSppArgument{"spp", 1, kMaxSamplesPerPixel};
inline constexpr ArgumentLimit kSeedArgument{"seed", 0, UINT32_MAX};
inline constexpr ArgumentLimit kThreadsArgument{"threads", 1, kMaxThreads};  // not given: thread_count()'s default
inline constexpr ArgumentLimit kTileTimeoutArgument{"tile_timeout", 1, 3600000};  // milliseconds
inline constexpr ArgumentLimit kBandCountArgument{"count", 1, kMaxBands};       // vkray.bands(scene, count)

// The device a session opens, and the shaders it compiles.
struct SessionOptions {
  std::string device;                // index or part of the name (`vkray devices`); empty: the best device
  bool validation = false;           // the Khronos validation layer; any message it prints is an error
  std::filesystem::path shader_dir;  // trace.comp and its includes; empty: the installed (or source) shaders
  // A window the device presents to (vkray view); null: headless.
  std::shared_ptr<const gpu::SurfaceRequest> surface;
};

// How the GPU path traces a scene of at most kMaxInlinePrimitives primitives.
enum class InlineScene {
  automatic,  // compiled in when the render traces enough camera rays to repay the longer compile
  always,     // compiled into the shader: every primitive tested with its coordinates as constants
  never,      // the BVH
};

struct RenderOptions {
  // Overrides of the scene file's image settings.
  std::optional<uint32_t> width, height, samples_per_pixel, seed;
  // false: no shadow rays, every light counts as visible (benchmarks of camera rays alone).
  bool shadows = true;
  // false: the path integrator finds the environment map by BSDF sampling alone, drawing no
  // directions from it: what importance sampling buys, measured (tools/bench-environment). Not for
  // the direct model, which samples no BSDF at a diffuse surface.
  bool sample_environment = true;
  // Also the first-hit passes (image/aovs.h): RenderResult::aovs.
  bool aovs = false;
  // Only these pixels (session/regions.h), each as in a render of the whole image; the result holds
  // just them. A band is resolved at the render, with the BVH the scene was uploaded with.
  std::optional<RegionRequest> region;
  // GPU: how a small scene is traced; the longest one submission (a tile) may run; square tiles of
  // this side in pixels (0: submissions sized by the time they take, gpu/tiling.h).
  InlineScene inline_scene = InlineScene::automatic;
  std::chrono::milliseconds tile_timeout{60000};
  uint32_t tile_side = 0;
  // CPU reference: threads (0: one per hardware thread; at most kMaxThreads). The image does not
  // depend on it.
  unsigned threads = 0;
  // Called as the render proceeds with the unit ("pixels" on the GPU, "rows" on the CPU), the units
  // done and the units in all.
  std::function<void(const char* unit, uint32_t done, uint32_t total)> progress;
  // A render stops on an interrupt request (base/interrupt.h) and throws Cancelled.
};

// The scene's image settings with the options' overrides. Every render resolves them first, so this
// is also where the options' numbers are checked: throws UsageError for an override, a thread count
// or a tile timeout outside its ArgumentLimit (an override's is the range a scene file may give).
ImageSettings image_settings(const Scene& scene, const RenderOptions& options);

struct RenderStats {
  double upload_seconds = 0;    // the frame's uniforms and output (a scene's own: DeviceScene)
  double trace_seconds = 0;
  double readback_seconds = 0;
  uint64_t rays = 0;            // camera rays + shadow rays
  uint32_t tiles = 0;           // GPU submissions
  unsigned threads = 0;         // CPU threads
  bool inline_scene = false;    // the GPU traced code compiled from the scene, not the BVH
};

struct RenderResult {
  Image image;  // linear radiance, top row first: the region's pixels
  std::optional<Aovs> aovs;  // when RenderOptions::aovs asked for them
  ImageSettings settings;    // the full image's, overrides applied
  PixelRegion region;        // the pixels rendered, in the full image's coordinates
  bool part = false;         // RenderOptions::region asked for them (even all of them): a part of a render
  // The hash (base/hash.h) of the shader folder's SPIR-V (a variant with the scene compiled in is
  // made from the same sources and the scene); empty: the CPU reference.
  std::string shader;
  RenderStats stats;
};

}  // namespace vkray
