#include "view/window.h"

#include <cstdlib>
#include <utility>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "base/errors.h"

namespace vkray::view {

// GLFW's callbacks, which find the Window through the window's user pointer.
struct Callbacks {
  static Window& of(GLFWwindow* w) { return *static_cast<Window*>(glfwGetWindowUserPointer(w)); }
  static void key(GLFWwindow* w, int key, int, int action, int mods) {
    of(w).events_.push_back({InputEvent::Kind::key, key, action, mods, {}});
  }
  static void button(GLFWwindow* w, int button, int action, int mods) {
    of(w).events_.push_back({InputEvent::Kind::button, button, action, mods, of(w).pointer_});
  }
  static void cursor(GLFWwindow* w, double x, double y) {
    of(w).pointer_ = {x, y};
    of(w).events_.push_back({InputEvent::Kind::cursor, 0, 0, 0, {x, y}});
  }
  static void scroll(GLFWwindow* w, double dx, double dy) {
    of(w).events_.push_back({InputEvent::Kind::scroll, 0, 0, 0, {dx, dy}});
  }
};

namespace {

std::string glfw_error() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "no reason given";
}

}  // namespace

Window::Window(const std::string& title, uint32_t width, uint32_t height) {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland))
    throw DeviceError("no display: DISPLAY (and WAYLAND_DISPLAY) are not set, so vkray view has nowhere to open its "
                      "window. Without a display, `vkray render` writes an image and `vkray watch` writes it again "
                      "whenever the scene or a shader changes");
  if (!glfwInit())
    throw DeviceError("cannot open a window on display " + std::string(display ? display : wayland) + ": " + glfw_error() +
                      ". Without a display, use `vkray render` or `vkray watch`");
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw DeviceError("GLFW finds no Vulkan loader for a window (libvulkan1)");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
  if (!window_) {
    const std::string reason = glfw_error();
    glfwTerminate();
    throw DeviceError("cannot open a window of " + std::to_string(width) + " x " + std::to_string(height) + ": " + reason);
  }
  glfwSetWindowUserPointer(window_, this);
  glfwGetCursorPos(window_, &pointer_.x, &pointer_.y);
  glfwSetKeyCallback(window_, Callbacks::key);
  glfwSetMouseButtonCallback(window_, Callbacks::button);
  glfwSetCursorPosCallback(window_, Callbacks::cursor);
  glfwSetScrollCallback(window_, Callbacks::scroll);
}

Window::~Window() {
  glfwDestroyWindow(window_);
  glfwTerminate();
}

std::shared_ptr<const gpu::SurfaceRequest> Window::surface_request() const {
  auto request = std::make_shared<gpu::SurfaceRequest>();
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  for (uint32_t i = 0; i < count; ++i) request->instance_extensions.emplace_back(names[i]);
  GLFWwindow* window = window_;
  request->create = [window](VkInstance instance) {
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    const VkResult result = glfwCreateWindowSurface(instance, window, nullptr, &surface);
    if (result != VK_SUCCESS)
      throw DeviceError("glfwCreateWindowSurface: " + std::to_string(int(result)) + ": " + glfw_error());
    return surface;
  };
  return request;
}

void Window::poll(double seconds) {
  if (seconds > 0.0) glfwWaitEventsTimeout(seconds);
  else glfwPollEvents();
}

std::vector<InputEvent> Window::take_events() { return std::exchange(events_, {}); }

bool Window::close_requested() const { return glfwWindowShouldClose(window_); }

glm::uvec2 Window::framebuffer_size() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return {uint32_t(std::max(w, 0)), uint32_t(std::max(h, 0))};
}

glm::dvec2 Window::cursor() const {
  double x = 0, y = 0;
  glfwGetCursorPos(window_, &x, &y);
  return {x, y};
}

void Window::set_title(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }

}  // namespace vkray::view
