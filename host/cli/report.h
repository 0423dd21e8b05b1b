// What the command line prints while it works, on stderr: warnings, a scene's summary, progress,
// rates; and the checks made before any work starts.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "base/timing.h"
#include "load/scene_loader.h"
#include "scene/scene.h"

namespace vkray::cli {

struct LoadedScene {
  std::shared_ptr<const Scene> scene;
  double load_ms = 0;
};
// Loads a scene file (lit by the environment map `environment` when it is not empty: load_scene)
// and prints its warnings.
LoadedScene load_scene_file(const std::filesystem::path& file, const std::filesystem::path& environment = {});

// "scenes/cornell.json: 30 triangles, 0 spheres, 1 lights; 512x512, 1 spp"
std::string describe(const Scene& scene, const ImageSettings& image);

// "8.08 Mrays/s"
std::string format_rate(uint64_t rays, double seconds);

// Shows progress once a render has taken about a second: in place on a terminal, else one line a
// second.
class Progress {
 public:
  Progress(bool enabled, const char* what);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(uint32_t done, uint32_t total, const char* unit);

 private:
  bool enabled_, tty_, shown_ = false;
  const char* what_;
  Clock::time_point start_ = Clock::now();
  double last_ = 0;
};

}  // namespace vkray::cli
