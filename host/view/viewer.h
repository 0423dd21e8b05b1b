// `vkray view`: a window that renders a scene progressively (session/progressive.h), moves its
// camera and first light with the lecture lab's keys and the mouse, reloads the scene and the
// shaders in place as `vkray watch` does, and saves what it has accumulated as `vkray render` writes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "image/exr.h"
#include "session/options.h"

namespace vkray::view {

struct ViewerOptions {
  std::filesystem::path scene;        // the scene file or glTF model
  std::filesystem::path environment;  // an environment map in place of the scene's; empty: none
  SessionOptions session;
  // The render: the image size opens the window at that size (a resize renders at the new size);
  // samples_per_pixel is where accumulation stops, with the image of `vkray render --spp N`.
  RenderOptions render;
  std::filesystem::path output;  // what P saves (and --exit-when-done); by extension, as render writes
  // Its display transform is the window's at the start; its passes (an EXR's first-hit passes) are
  // accumulated with the image.
  OutputContent content;
  bool exit_when_done = false;   // save and exit once every pixel has all its samples
  // A JSON line per frame that traced or answered input: seconds since the start and since the
  // epoch, the frame's time, samples, restarts, and how long the input or reload it shows waited
  // (what `tools/bench-view` measures). Empty: none.
  std::filesystem::path frame_log;
};

// Runs until the window is closed or Escape; returns the exit code. Throws DeviceError (no display,
// no device that presents), and what loading the scene throws before the window opens.
int run_viewer(const ViewerOptions& options);

}  // namespace vkray::view
