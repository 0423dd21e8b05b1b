#include "view/presenter.h"

#include <algorithm>
#include <cstring>

#include "base/errors.h"

namespace vkray::view {
namespace {

// The longest a frame's fence or an image's acquisition is waited for.
constexpr std::chrono::milliseconds kFrameTimeout{10000};

vk::ImageSubresourceRange colour_range() { return {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1}; }

void image_barrier(const vk::raii::CommandBuffer& cb, vk::Image image, vk::ImageLayout from, vk::ImageLayout to,
                   vk::PipelineStageFlags src_stage, vk::AccessFlags src_access, vk::PipelineStageFlags dst_stage,
                   vk::AccessFlags dst_access) {
  const vk::ImageMemoryBarrier barrier(src_access, dst_access, from, to, VK_QUEUE_FAMILY_IGNORED, VK_QUEUE_FAMILY_IGNORED, image,
                                       colour_range());
  cb.pipelineBarrier(src_stage, dst_stage, {}, {}, {}, barrier);
}

}  // namespace

Presenter::Presenter(const gpu::Context& ctx) : ctx_(&ctx) {
  const vk::raii::PhysicalDevice& pd = ctx_->physical_device();
  const vk::SurfaceKHR surface = *ctx_->surface();
  // Pixels are copied in as 8-bit sRGB-encoded values, so a UNORM format shows them as they are
  // (an _SRGB one would too, but would draw the overlay's colours lighter).
  const auto formats = pd.getSurfaceFormatsKHR(surface);
  const auto find = [&](vk::Format f) {
    return std::find_if(formats.begin(), formats.end(), [&](const vk::SurfaceFormatKHR& s) {
      return s.format == f && s.colorSpace == vk::ColorSpaceKHR::eSrgbNonlinear;
    });
  };
  auto chosen = find(vk::Format::eB8G8R8A8Unorm);
  if (chosen == formats.end()) chosen = find(vk::Format::eR8G8B8A8Unorm);
  if (chosen == formats.end()) chosen = find(vk::Format::eB8G8R8A8Srgb);
  if (chosen == formats.end()) chosen = find(vk::Format::eR8G8B8A8Srgb);
  if (chosen == formats.end()) throw DeviceError(ctx_->device_name() + " offers the window no 8-bit RGBA or BGRA format");
  format_ = *chosen;
  order_ = format_.format == vk::Format::eB8G8R8A8Unorm || format_.format == vk::Format::eB8G8R8A8Srgb ? PixelOrder::bgra
                                                                                                       : PixelOrder::rgba;
  const vk::SurfaceCapabilitiesKHR caps = pd.getSurfaceCapabilitiesKHR(surface);
  using U = vk::ImageUsageFlagBits;
  if (!(caps.supportedUsageFlags & U::eTransferDst) || !(caps.supportedUsageFlags & U::eColorAttachment))
    throw DeviceError(ctx_->device_name() + "'s window images cannot be copied to and drawn on");
  can_read_back_ = bool(caps.supportedUsageFlags & U::eTransferSrc);
  // Mailbox, then immediate: a frame is never held for the display's refresh, so input is answered
  // at the pace the device renders; FIFO (always there) otherwise.
  const auto modes = pd.getSurfacePresentModesKHR(surface);
  for (vk::PresentModeKHR mode : {vk::PresentModeKHR::eMailbox, vk::PresentModeKHR::eImmediate})
    if (std::find(modes.begin(), modes.end(), mode) != modes.end()) {
      present_mode_ = mode;
      break;
    }

  // The overlay's pass: it draws over the pixels copied in, and leaves the image for presenting.
  const vk::AttachmentDescription attachment({}, format_.format, vk::SampleCountFlagBits::e1, vk::AttachmentLoadOp::eLoad,
                                             vk::AttachmentStoreOp::eStore, vk::AttachmentLoadOp::eDontCare,
                                             vk::AttachmentStoreOp::eDontCare, vk::ImageLayout::eTransferDstOptimal,
                                             vk::ImageLayout::ePresentSrcKHR);
  const vk::AttachmentReference colour(0, vk::ImageLayout::eColorAttachmentOptimal);
  const vk::SubpassDescription subpass({}, vk::PipelineBindPoint::eGraphics, {}, colour);
  const vk::SubpassDependency after_copy(
      VK_SUBPASS_EXTERNAL, 0, vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eColorAttachmentOutput,
      vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eColorAttachmentRead | vk::AccessFlagBits::eColorAttachmentWrite);
  // And before a read back (F12) copies the image out, after the pass's final layout transition.
  const vk::SubpassDependency before_read_back(0, VK_SUBPASS_EXTERNAL, vk::PipelineStageFlagBits::eColorAttachmentOutput,
                                               vk::PipelineStageFlagBits::eTransfer, vk::AccessFlagBits::eColorAttachmentWrite,
                                               vk::AccessFlagBits::eTransferRead);
  const vk::SubpassDependency dependencies[] = {after_copy, before_read_back};
  render_pass_ = vk::raii::RenderPass(ctx_->device(), vk::RenderPassCreateInfo({}, attachment, subpass, dependencies));

  acquired_ = vk::raii::Semaphore(ctx_->device(), vk::SemaphoreCreateInfo{});
  pool_ = vk::raii::CommandPool(ctx_->device(), {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, ctx_->queue_family()});
  commands_ = std::move(vk::raii::CommandBuffers(ctx_->device(), {*pool_, vk::CommandBufferLevel::ePrimary, 1})[0]);
  done_ = vk::raii::Fence(ctx_->device(), vk::FenceCreateInfo{});
}

Presenter::~Presenter() {
  try {
    if (in_flight_) ctx_->wait(done_, kFrameTimeout, "the last frame");
    ctx_->queue().waitIdle();  // the last present
  } catch (...) {  // a lost device: nothing is running any more
  }
}

void Presenter::create_swapchain(vk::Extent2D size) {
  if (in_flight_) {
    ctx_->wait(done_, kFrameTimeout, "a frame");
    in_flight_ = false;
    ctx_->device().resetFences(*done_);
  }
  ctx_->queue().waitIdle();  // presents of the old swapchain's images
  const vk::SurfaceCapabilitiesKHR caps = ctx_->physical_device().getSurfaceCapabilitiesKHR(*ctx_->surface());
  vk::Extent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX)
    extent = vk::Extent2D(std::clamp(size.width, caps.minImageExtent.width, caps.maxImageExtent.width),
                          std::clamp(size.height, caps.minImageExtent.height, caps.maxImageExtent.height));
  framebuffers_.clear();
  views_.clear();
  images_.clear();
  rendered_.clear();
  extent_ = extent;
  stale_ = false;
  if (extent.width == 0 || extent.height == 0) {
    swapchain_ = vk::raii::SwapchainKHR(nullptr);
    return;
  }
  min_image_count_ = std::max(caps.minImageCount, 2u);
  uint32_t count = min_image_count_ + 1;
  if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);
  using U = vk::ImageUsageFlagBits;
  const vk::ImageUsageFlags usage = U::eColorAttachment | U::eTransferDst | (can_read_back_ ? U::eTransferSrc : U{});
  vk::SwapchainCreateInfoKHR info({}, *ctx_->surface(), count, format_.format, format_.colorSpace, extent, 1, usage,
                                  vk::SharingMode::eExclusive, {}, caps.currentTransform,
                                  vk::CompositeAlphaFlagBitsKHR::eOpaque, present_mode_, VK_TRUE, *swapchain_);
  if (!(caps.supportedCompositeAlpha & vk::CompositeAlphaFlagBitsKHR::eOpaque))
    info.compositeAlpha = vk::CompositeAlphaFlagBitsKHR::eInherit;
  swapchain_ = vk::raii::SwapchainKHR(ctx_->device(), info);
  images_ = swapchain_.getImages();
  for (vk::Image image : images_) {
    views_.emplace_back(ctx_->device(), vk::ImageViewCreateInfo({}, image, vk::ImageViewType::e2D, format_.format, {}, colour_range()));
    framebuffers_.emplace_back(ctx_->device(),
                               vk::FramebufferCreateInfo({}, *render_pass_, *views_.back(), extent.width, extent.height, 1));
    rendered_.emplace_back(ctx_->device(), vk::SemaphoreCreateInfo{});
  }
}

void Presenter::ensure_staging(vk::DeviceSize bytes) {
  if (bytes <= staging_bytes_) return;
  using M = vk::MemoryPropertyFlagBits;
  staging_ = gpu::create_buffer(*ctx_, bytes, vk::BufferUsageFlagBits::eTransferSrc, M::eHostVisible | M::eHostCoherent);
  staging_bytes_ = bytes;
}

void Presenter::record(uint32_t index, const uint8_t* pixels, uint32_t width, uint32_t height,
                       const std::function<void(vk::CommandBuffer)>& overlay, bool read_back) {
  using S = vk::PipelineStageFlagBits;
  using A = vk::AccessFlagBits;
  using L = vk::ImageLayout;
  const vk::Image image = images_[index];
  const vk::raii::CommandBuffer& cb = commands_;
  cb.reset();
  cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  // The image's old contents are of no use: cleared to black, then the pixels copied in.
  image_barrier(cb, image, L::eUndefined, L::eTransferDstOptimal, S::eTransfer, {}, S::eTransfer, A::eTransferWrite);
  cb.clearColorImage(image, L::eTransferDstOptimal, vk::ClearColorValue(std::array<float, 4>{0.0f, 0.0f, 0.0f, 1.0f}),
                     colour_range());
  if (pixels && width > 0 && height > 0) {
    image_barrier(cb, image, L::eTransferDstOptimal, L::eTransferDstOptimal, S::eTransfer, A::eTransferWrite, S::eTransfer,
                  A::eTransferWrite);
    const vk::BufferImageCopy region(0, width, height, {vk::ImageAspectFlagBits::eColor, 0, 0, 1}, {0, 0, 0},
                                     {std::min(width, extent_.width), std::min(height, extent_.height), 1});
    cb.copyBufferToImage(*staging_.buffer, image, L::eTransferDstOptimal, region);
  }
  const vk::ClearValue unused;
  cb.beginRenderPass(vk::RenderPassBeginInfo(*render_pass_, *framebuffers_[index], vk::Rect2D({0, 0}, extent_), unused),
                     vk::SubpassContents::eInline);
  if (overlay) overlay(*cb);
  cb.endRenderPass();
  if (read_back) {
    image_barrier(cb, image, L::ePresentSrcKHR, L::eTransferSrcOptimal, S::eColorAttachmentOutput, A::eColorAttachmentWrite,
                  S::eTransfer, A::eTransferRead);
    const vk::BufferImageCopy region(0, 0, 0, {vk::ImageAspectFlagBits::eColor, 0, 0, 1}, {0, 0, 0},
                                     {extent_.width, extent_.height, 1});
    cb.copyImageToBuffer(image, L::eTransferSrcOptimal, *read_back_.buffer, region);
    image_barrier(cb, image, L::eTransferSrcOptimal, L::ePresentSrcKHR, S::eTransfer, A::eTransferRead, S::eBottomOfPipe, {});
    const vk::MemoryBarrier to_host(A::eTransferWrite, A::eHostRead);
    cb.pipelineBarrier(S::eTransfer, S::eHost, {}, to_host, {}, {});
  }
  cb.end();
}

bool Presenter::present(vk::Extent2D size, const uint8_t* pixels, uint32_t width, uint32_t height,
                        const std::function<void(vk::CommandBuffer)>& overlay, std::vector<uint8_t>* read_back) {
  if (size.width == 0 || size.height == 0) return false;
  if (!*swapchain_ || stale_ || size != extent_) create_swapchain(size);
  if (!*swapchain_) return false;
  if (in_flight_) {
    ctx_->wait(done_, kFrameTimeout, "the last frame");
    in_flight_ = false;
    ctx_->device().resetFences(*done_);
  }
  uint32_t index = 0;
  try {
    const auto [result, acquired] =
        swapchain_.acquireNextImage(uint64_t(std::chrono::nanoseconds(kFrameTimeout).count()), *acquired_);
    if (result == vk::Result::eTimeout || result == vk::Result::eNotReady)
      throw TimeoutError("vkAcquireNextImageKHR: no window image within " + std::to_string(kFrameTimeout.count()) + " ms");
    index = acquired;
  } catch (const vk::OutOfDateKHRError&) {
    stale_ = true;  // made again next frame
    return false;
  }
  const bool reading = read_back && can_read_back_;
  if (reading && read_back_bytes_ < vk::DeviceSize(extent_.width) * extent_.height * 4) {
    using M = vk::MemoryPropertyFlagBits;
    read_back_bytes_ = vk::DeviceSize(extent_.width) * extent_.height * 4;
    read_back_ = gpu::create_buffer(*ctx_, read_back_bytes_, vk::BufferUsageFlagBits::eTransferDst, M::eHostVisible,
                                    M::eHostCached);
  }
  if (pixels) {
    ensure_staging(vk::DeviceSize(width) * height * 4);
    std::memcpy(staging_.mapped, pixels, size_t(width) * height * 4);
  }
  record(index, pixels, width, height, overlay, reading);
  const vk::PipelineStageFlags wait_stage = vk::PipelineStageFlagBits::eTransfer;
  const vk::CommandBuffer raw = *commands_;
  const vk::Semaphore signal = *rendered_[index];
  ctx_->queue().submit(vk::SubmitInfo(*acquired_, wait_stage, raw, signal), *done_);
  in_flight_ = true;
  try {
    const vk::SwapchainKHR chain = *swapchain_;
    const vk::Result result = ctx_->queue().presentKHR(vk::PresentInfoKHR(signal, chain, index));
    if (result == vk::Result::eSuboptimalKHR) stale_ = true;
  } catch (const vk::OutOfDateKHRError&) {
    stale_ = true;
  }
  if (reading) {
    ctx_->wait(done_, kFrameTimeout, "a frame read back");
    in_flight_ = false;
    ctx_->device().resetFences(*done_);
    read_back_.invalidate(ctx_->device());
    const size_t bytes = size_t(extent_.width) * extent_.height * 4;
    read_back->resize(bytes);
    const auto* from = static_cast<const uint8_t*>(read_back_.mapped);
    for (size_t i = 0; i < bytes; i += 4) {
      const bool bgra = order_ == PixelOrder::bgra;
      (*read_back)[i + 0] = from[i + (bgra ? 2 : 0)];
      (*read_back)[i + 1] = from[i + 1];
      (*read_back)[i + 2] = from[i + (bgra ? 0 : 2)];
      (*read_back)[i + 3] = 255;
    }
  } else if (read_back) {
    read_back->clear();
  }
  return true;
}

}  // namespace vkray::view
