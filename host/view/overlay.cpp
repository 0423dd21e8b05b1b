#include "view/overlay.h"

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>

#include "base/errors.h"
#include "view/presenter.h"

namespace vkray::view {
namespace {

void check_vk(VkResult result) {
  if (result < 0) throw DeviceError("the overlay's Vulkan call failed: " + vk::to_string(vk::Result(result)));
}

// Panels that take no input: every key and drag goes to the viewer.
constexpr ImGuiWindowFlags kPanel = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                    ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                    ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoInputs;

}  // namespace

Overlay::Overlay(GLFWwindow* window, const gpu::Context& ctx, const Presenter& presenter)
    : ctx_(&ctx), min_image_count_(presenter.min_image_count()) {
  // The backend's pipeline needs one combined image sampler (the font atlas).
  const vk::DescriptorPoolSize size(vk::DescriptorType::eCombinedImageSampler, 1);
  pool_ = vk::raii::DescriptorPool(ctx_->device(),
                                   vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, size));
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini written into the user's folder
  io.LogFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 4.0f;
  ImGui_ImplGlfw_InitForVulkan(window, true);
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = *ctx_->instance();
  info.PhysicalDevice = *ctx_->physical_device();
  info.Device = *ctx_->device();
  info.QueueFamily = ctx_->queue_family();
  info.Queue = *ctx_->queue();
  info.DescriptorPool = *pool_;
  info.MinImageCount = std::max(presenter.min_image_count(), 2u);
  info.ImageCount = std::max(presenter.image_count(), info.MinImageCount);
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = check_vk;
  ImGui_ImplVulkan_Init(&info, presenter.render_pass());

  // The font atlas, uploaded once.
  vk::raii::CommandPool pool(ctx_->device(), {vk::CommandPoolCreateFlagBits::eTransient, ctx_->queue_family()});
  vk::raii::CommandBuffer cb = std::move(vk::raii::CommandBuffers(ctx_->device(), {*pool, vk::CommandBufferLevel::ePrimary, 1})[0]);
  cb.begin({vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  ImGui_ImplVulkan_CreateFontsTexture(*cb);
  cb.end();
  vk::raii::Fence fence(ctx_->device(), vk::FenceCreateInfo{});
  const vk::CommandBuffer raw = *cb;
  ctx_->queue().submit(vk::SubmitInfo({}, {}, raw), *fence);
  ctx_->wait(fence, std::chrono::milliseconds(10000), "the overlay's font upload");
  ImGui_ImplVulkan_DestroyFontUploadObjects();
}

Overlay::~Overlay() {
  try {
    ctx_->device().waitIdle();
  } catch (...) {
  }
  ImGui_ImplVulkan_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void Overlay::set_image_count(uint32_t min_image_count) {
  if (min_image_count == min_image_count_) return;
  min_image_count_ = min_image_count;
  ImGui_ImplVulkan_SetMinImageCount(std::max(min_image_count, 2u));
}

void Overlay::build(const OverlayContent& content) {
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  if (content.show) {
    ImGui::SetNextWindowPos(ImVec2(8, 8));
    ImGui::SetNextWindowBgAlpha(0.75f);
    ImGui::Begin("status", nullptr, kPanel);
    for (const std::string& line : content.status) ImGui::TextUnformatted(line.c_str());
    ImGui::Separator();
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 36.0f);
    ImGui::TextUnformatted(content.camera_json.c_str());
    ImGui::PopTextWrapPos();
    ImGui::TextDisabled("F1: keys   Tab: hide");
    // The keys go below the status, where a small window still has room for both.
    const float below = ImGui::GetWindowPos().y + ImGui::GetWindowSize().y + 8.0f;
    ImGui::End();
    if (content.show_help) {
      ImGui::SetNextWindowPos(ImVec2(8, below));
      ImGui::SetNextWindowBgAlpha(0.75f);
      ImGui::Begin("keys", nullptr, kPanel);
      if (ImGui::BeginTable("keys", 2)) {
        for (const auto& [key, action] : content.keys) {
          ImGui::TableNextRow();
          ImGui::TableSetColumnIndex(0);
          ImGui::TextUnformatted(key.c_str());
          ImGui::TableSetColumnIndex(1);
          ImGui::TextUnformatted(action.c_str());
        }
        ImGui::EndTable();
      }
      ImGui::End();
    }
    if (!content.message.empty()) {
      const ImVec2 display = ImGui::GetIO().DisplaySize;
      ImGui::SetNextWindowPos(ImVec2(8, display.y - 8), ImGuiCond_Always, ImVec2(0, 1));
      ImGui::SetNextWindowBgAlpha(0.75f);
      ImGui::Begin("message", nullptr, kPanel);
      ImGui::PushTextWrapPos(display.x - 32.0f);
      if (content.message_is_error) ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 120, 110, 255));
      ImGui::TextUnformatted(content.message.c_str());
      if (content.message_is_error) ImGui::PopStyleColor();
      ImGui::PopTextWrapPos();
      ImGui::End();
    }
  }
  ImGui::Render();
}

void Overlay::record(vk::CommandBuffer cb) { ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cb); }

}  // namespace vkray::view
