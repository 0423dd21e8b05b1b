// Shows `vkray view`'s pixels in its window: a swapchain on the device's queue, each frame's 8-bit
// pixels copied into the acquired image, an overlay drawn over them in a render pass, and the image
// presented. It also reads the window's pixels back (what is on screen, overlay included) when asked.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/buffer.h"
#include "gpu/context.h"

namespace vkray::view {

// 8-bit pixels as the swapchain's format orders them.
enum class PixelOrder { rgba, bgra };

class Presenter {
 public:
  // On ctx's surface (gpu::Context made with a SurfaceRequest). Throws DeviceError when the surface
  // offers no 8-bit format or cannot be copied to.
  explicit Presenter(const gpu::Context& ctx);
  ~Presenter();  // waits for the device to finish the last frame
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  PixelOrder order() const { return order_; }
  vk::RenderPass render_pass() const { return *render_pass_; }
  uint32_t min_image_count() const { return min_image_count_; }
  uint32_t image_count() const { return uint32_t(images_.size()); }
  // The swapchain's size in pixels (0 x 0 before the first frame, and while minimised).
  vk::Extent2D extent() const { return extent_; }

  // One frame for a window of `size` pixels: the swapchain is made again when the size changed or
  // the surface says it is out of date. `pixels` (width x height, 4 bytes each in order()) lands at
  // the top left, the rest is black; `overlay` records its draws inside the render pass. With
  // `read_back`, the frame as presented is copied into it (extent() pixels, RGBA). Returns false,
  // having shown nothing, while the window has no area (minimised).
  bool present(vk::Extent2D size, const uint8_t* pixels, uint32_t width, uint32_t height,
               const std::function<void(vk::CommandBuffer)>& overlay, std::vector<uint8_t>* read_back = nullptr);

 private:
  void create_swapchain(vk::Extent2D size);
  void ensure_staging(vk::DeviceSize bytes);
  void record(uint32_t image, const uint8_t* pixels, uint32_t width, uint32_t height,
              const std::function<void(vk::CommandBuffer)>& overlay, bool read_back);

  const gpu::Context* ctx_;  // the session's, which outlives this
  vk::SurfaceFormatKHR format_;
  PixelOrder order_ = PixelOrder::bgra;
  vk::PresentModeKHR present_mode_ = vk::PresentModeKHR::eFifo;
  uint32_t min_image_count_ = 2;
  bool can_read_back_ = false;
  vk::raii::RenderPass render_pass_{nullptr};
  vk::Extent2D extent_{0, 0};
  vk::raii::SwapchainKHR swapchain_{nullptr};
  bool stale_ = false;  // out of date or suboptimal: made again at the next frame
  std::vector<vk::Image> images_;
  std::vector<vk::raii::ImageView> views_;
  std::vector<vk::raii::Framebuffer> framebuffers_;
  std::vector<vk::raii::Semaphore> rendered_;  // one per image: its present waits on it
  vk::raii::Semaphore acquired_{nullptr};
  vk::raii::CommandPool pool_{nullptr};
  vk::raii::CommandBuffer commands_{nullptr};
  vk::raii::Fence done_{nullptr};  // the last frame's submission
  bool in_flight_ = false;
  gpu::Buffer staging_;             // the frame's pixels
  vk::DeviceSize staging_bytes_ = 0;
  gpu::Buffer read_back_;           // the window's pixels, when asked for
  vk::DeviceSize read_back_bytes_ = 0;
};

}  // namespace vkray::view
