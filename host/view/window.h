// `vkray view`'s window (GLFW): its surface for the device, and the input that arrived since the
// last frame as a list of events, so that the viewer handles input in one place, in order.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/surface_request.h"

struct GLFWwindow;

namespace vkray::view {

struct InputEvent {
  enum class Kind { key, button, cursor, scroll };
  Kind kind = Kind::key;
  int key = 0;     // key: GLFW_KEY_*; button: GLFW_MOUSE_BUTTON_*
  int action = 0;  // GLFW_PRESS, GLFW_REPEAT, GLFW_RELEASE
  int mods = 0;    // GLFW_MOD_*
  glm::dvec2 position{0.0};  // cursor: window coordinates; scroll: the offsets
};

class Window {
 public:
  // Opens a window of `width` x `height` screen coordinates. Throws DeviceError when there is no
  // display to open it on (saying what to use instead), or GLFW has no Vulkan.
  Window(const std::string& title, uint32_t width, uint32_t height);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  GLFWwindow* handle() const { return window_; }
  // What the device needs to present here (SessionOptions::surface).
  std::shared_ptr<const gpu::SurfaceRequest> surface_request() const;

  // Handles the window system's events, waiting up to `seconds` for one when there is none (0:
  // not at all).
  void poll(double seconds = 0.0);
  // The input since the last call, in order.
  std::vector<InputEvent> take_events();
  bool close_requested() const;
  // In pixels (0 x 0 while minimised).
  glm::uvec2 framebuffer_size() const;
  glm::dvec2 cursor() const;
  void set_title(const std::string& title);

 private:
  friend struct Callbacks;
  GLFWwindow* window_ = nullptr;
  std::vector<InputEvent> events_;
  // Where the last cursor event put the pointer: a button event happened there (asking the server
  // instead gives where the pointer is now, past motion still queued).
  glm::dvec2 pointer_{0.0};
};

}  // namespace vkray::view
