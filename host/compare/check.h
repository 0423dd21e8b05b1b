// `vkray check`'s suite: whether a device and its driver render vkray's contract. Every shipped scene
// and every adversarial case (checks/: grazing rays, shared edges, a light on a surface, scenes at
// the coordinate limit, ...), each on the BVH and, when it is small enough, compiled into the shader,
// at 1 and 16 samples per pixel, against the CPU reference (compare/parity.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "session/options.h"
#include "compare/parity.h"

namespace vkray {

class Session;

struct CheckCase {
  std::filesystem::path scene;  // the scene file
  InlineScene path = InlineScene::never;  // never: the BVH; always: the scene compiled into the shader
  uint32_t samples_per_pixel = 1;
};
// "bvh" or "inline"
const char* path_name(InlineScene path);
// "light-on-surface/inline/16spp": the scene file's stem, the path and the sample count.
std::string case_name(const CheckCase& c);

struct CheckResult {
  CheckCase c;
  std::string description;  // the scene's own ("description" in the file), or empty
  ParityResult parity;      // images, metrics and tolerance
  // The case's GPU render and comparison, and for the first path of each sample count the CPU
  // reference both paths share, so that the cases' seconds add up to the check's.
  double seconds = 0;
};

struct CheckOptions {
  std::vector<std::filesystem::path> scenes;  // in the order they run (check_scenes())
  uint32_t width = 256, height = 256;         // every case's image, whatever its file says
  std::vector<uint32_t> samples_per_pixel{1, 16};
  RenderOptions render;  // the tile timeout and the CPU threads; the rest is set per case
  // Called before each scene is loaded, before each case, and after each case with its result
  // (which is then dropped: a check at 2048 x 2048 would otherwise hold every case's images).
  std::function<void(const std::filesystem::path& scene)> on_scene;
  std::function<void(const CheckCase&)> on_case;
  std::function<void(const CheckResult&)> on_result;
};

// The suite's scene files: every *.json in each folder, each folder's sorted by name. Two files of
// one name (the name of their cases) are an InternalError.
std::vector<std::filesystem::path> check_scenes(const std::vector<std::filesystem::path>& folders);

// "20 scenes at 256x256, each on the BVH and, with 64 primitives or fewer, compiled into the shader;
// at 1 and 16 spp": what run_check will do.
std::string describe_plan(const CheckOptions& options);

// Runs every case on the session's device. Each scene is loaded, its BVH built and uploaded once,
// and the CPU reference rendered once per sample count for both paths. Throws what loading or
// rendering throws (SceneError, DeviceError, TimeoutError, Cancelled, ...): a case that cannot run
// ends the check.
void run_check(Session& session, const CheckOptions& options);

}  // namespace vkray
