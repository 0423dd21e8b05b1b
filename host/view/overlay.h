// `vkray view`'s overlay (Dear ImGui, through its GLFW and Vulkan backends): the status panel
// (samples, frame time, samples per second, device, the camera as scene JSON), the help panel with
// every key, and the last message (a reload's error, a saved file).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

struct GLFWwindow;

namespace vkray::view {

class Presenter;

struct OverlayContent {
  bool show = true;        // Tab hides both panels (the message too)
  bool show_help = false;  // F1, H or ?
  std::vector<std::string> status;  // a line each
  std::string camera_json;          // selectable, to copy into a scene file
  std::vector<std::pair<std::string, std::string>> keys;  // key, what it does
  std::string message;              // the last reload error or save; empty: none
  bool message_is_error = false;
};

class Overlay {
 public:
  // After the window's own callbacks are set: ImGui's chain to them.
  Overlay(GLFWwindow* window, const gpu::Context& ctx, const Presenter& presenter);
  ~Overlay();
  Overlay(const Overlay&) = delete;
  Overlay& operator=(const Overlay&) = delete;

  // Lays out this frame's panels; record() then draws them into the presenter's render pass.
  void build(const OverlayContent& content);
  void record(vk::CommandBuffer cb);
  // The swapchain was made again with this many images.
  void set_image_count(uint32_t min_image_count);

 private:
  const gpu::Context* ctx_;  // the session's, which outlives this
  vk::raii::DescriptorPool pool_{nullptr};
  uint32_t min_image_count_ = 0;
};

}  // namespace vkray::view
