#include "cli/report.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>

#include "base/errors.h"
#include "image/image.h"
#include "image/image_file.h"
#include "load/scene_loader.h"

namespace vkray::cli {

LoadedScene load_scene_file(const std::filesystem::path& file, const std::filesystem::path& environment) {
  const auto start = Clock::now();
  LoadedScene loaded;
  loaded.scene = std::make_shared<const Scene>(load_scene(file, nullptr, environment));
  for (const auto& warning : loaded.scene->warnings) std::cerr << "vkray: warning: " << warning << "\n";
  loaded.load_ms = ms_since(start);
  return loaded;
}

std::string describe(const Scene& scene, const ImageSettings& image) {
  std::string instances;
  if (!scene.instances.empty()) {
    const PrimitiveNumbering numbering(scene);
    instances = " (and " + std::to_string(scene.instances.size()) + " instances of " + std::to_string(scene.meshes.size()) +
                (scene.meshes.size() == 1 ? " mesh" : " meshes") + ", " +
                std::to_string(numbering.sphere_first() - scene.triangles.size()) + " triangles placed)";
  }
  return printable(scene.file.string(), 200) + ": " + std::to_string(scene.triangles.size()) + " triangles" + instances + ", " +
         std::to_string(scene.spheres.size()) + " spheres, " + std::to_string(scene.lights.size()) + " lights; " +
         std::to_string(image.width) + "x" + std::to_string(image.height) + ", " +
         std::to_string(image.samples_per_pixel) + " spp";
}

std::string format_rate(uint64_t rays, double seconds) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2f Mrays/s", seconds > 0 ? double(rays) / seconds * 1e-6 : 0.0);
  return buffer;
}

Progress::Progress(bool enabled, const char* what) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1), what_(what) {}

Progress::~Progress() {
  if (shown_ && tty_) std::cerr << "\n";
}

void Progress::update(uint32_t done, uint32_t total, const char* unit) {
  const double elapsed = ms_since(start_);
  if (!enabled_ || elapsed < 1000.0 || (done == total && !shown_)) return;
  if (!tty_ && elapsed - last_ < 1000.0 && done != total) return;
  last_ = elapsed;
  shown_ = true;
  // The time left at the rate so far (the first units hold start-up costs, so it errs long).
  std::string left;
  if (done > 0 && done < total) {
    const double seconds = elapsed / 1000.0 * double(total - done) / double(done);
    char text[64];
    if (seconds < 90) std::snprintf(text, sizeof text, ", about %.0f s left", std::max(1.0, seconds));
    else std::snprintf(text, sizeof text, ", about %.0f min left", seconds / 60.0);
    left = text;
  }
  std::cerr << (tty_ ? "\r" : "") << "vkray: " << what_ << " " << (100 * uint64_t(done) / total) << "% (" << done << "/"
            << total << " " << unit << left << ")" << (tty_ ? "\033[K" : "\n") << std::flush;
}

}  // namespace vkray::cli
