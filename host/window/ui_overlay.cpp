// ui_overlay.cpp — see ui_overlay.h.
#include "window/ui_overlay.h"

#include <fmt/format.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include "core/error.h"

namespace obscura::window {
namespace {

void checkVk(VkResult result) {
  if (result != VK_SUCCESS)
    throw DeviceError(fmt::format("view: the panel's Vulkan backend failed: {}", vk::to_string(static_cast<vk::Result>(result))));
}

} // namespace

UiOverlay::UiOverlay(const gpu::Context& context, GlfwWindow& window, const Swapchain& swapchain)
    : context_(&context), swapchain_(&swapchain) {
  const auto& device = context.device();
  const vk::DescriptorPoolSize sizes[] = {{vk::DescriptorType::eCombinedImageSampler, 16}};
  pool_ = vk::raii::DescriptorPool(device, vk::DescriptorPoolCreateInfo{
                                               .flags = vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet,
                                               .maxSets = 16,
                                               .poolSizeCount = 1,
                                               .pPoolSizes = sizes});
  vk::AttachmentDescription color{.format = swapchain.format(),
                                  .samples = vk::SampleCountFlagBits::e1,
                                  .loadOp = vk::AttachmentLoadOp::eLoad,
                                  .storeOp = vk::AttachmentStoreOp::eStore,
                                  .stencilLoadOp = vk::AttachmentLoadOp::eDontCare,
                                  .stencilStoreOp = vk::AttachmentStoreOp::eDontCare,
                                  .initialLayout = vk::ImageLayout::eColorAttachmentOptimal,
                                  .finalLayout = vk::ImageLayout::eColorAttachmentOptimal};
  vk::AttachmentReference reference{0, vk::ImageLayout::eColorAttachmentOptimal};
  vk::SubpassDescription subpass{.pipelineBindPoint = vk::PipelineBindPoint::eGraphics,
                                 .colorAttachmentCount = 1,
                                 .pColorAttachments = &reference};
  // The blit into the image (a transfer) must be done before the panel blends over it.
  vk::SubpassDependency dependency{.srcSubpass = VK_SUBPASS_EXTERNAL,
                                   .dstSubpass = 0,
                                   .srcStageMask = vk::PipelineStageFlagBits::eTransfer |
                                                   vk::PipelineStageFlagBits::eColorAttachmentOutput,
                                   .dstStageMask = vk::PipelineStageFlagBits::eColorAttachmentOutput,
                                   .srcAccessMask = vk::AccessFlagBits::eTransferWrite,
                                   .dstAccessMask = vk::AccessFlagBits::eColorAttachmentRead |
                                                    vk::AccessFlagBits::eColorAttachmentWrite};
  renderPass_ = vk::raii::RenderPass(device, vk::RenderPassCreateInfo{.attachmentCount = 1,
                                                                      .pAttachments = &color,
                                                                      .subpassCount = 1,
                                                                      .pSubpasses = &subpass,
                                                                      .dependencyCount = 1,
                                                                      .pDependencies = &dependency});

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr; // no imgui.ini left in the user's folder
  ImGui::StyleColorsDark();
  ImGui::GetStyle().Alpha = 0.92f;
  // Installs ImGui's callbacks, which call the window's own (installed before) first.
  ImGui_ImplGlfw_InitForVulkan(window.handle(), true);
  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = *context.instance();
  info.PhysicalDevice = *context.physicalDevice();
  info.Device = *device;
  info.QueueFamily = context.queueFamily();
  info.Queue = *context.queue();
  info.DescriptorPool = *pool_;
  info.MinImageCount = 2;
  info.ImageCount = static_cast<std::uint32_t>(std::max<std::size_t>(2, swapchain.imageCount()));
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = checkVk;
  if (!ImGui_ImplVulkan_Init(&info, *renderPass_)) throw DeviceError("view: the panel's Vulkan backend did not start");
  context.submitAndWait([](const vk::raii::CommandBuffer& cmd) { ImGui_ImplVulkan_CreateFontsTexture(*cmd); });
  ImGui_ImplVulkan_DestroyFontUploadObjects();
  makeFramebuffers();
}

UiOverlay::~UiOverlay() {
  context_->device().waitIdle();
  if (frameOpen_) ImGui::EndFrame();
  ImGui_ImplVulkan_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void UiOverlay::makeFramebuffers() {
  framebuffers_.clear();
  const vk::Extent2D extent = swapchain_->extent();
  for (std::size_t i = 0; i < swapchain_->imageCount(); ++i) {
    vk::ImageView view = *swapchain_->view(i);
    framebuffers_.emplace_back(context_->device(), vk::FramebufferCreateInfo{.renderPass = *renderPass_,
                                                                             .attachmentCount = 1,
                                                                             .pAttachments = &view,
                                                                             .width = extent.width,
                                                                             .height = extent.height,
                                                                             .layers = 1});
  }
  generation_ = swapchain_->generation();
  ImGui_ImplVulkan_SetMinImageCount(2);
}

void UiOverlay::beginFrame(InputState& input) {
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  frameOpen_ = true;
  input.uiWantsMouse = ImGui::GetIO().WantCaptureMouse;
  input.uiWantsKeyboard = ImGui::GetIO().WantCaptureKeyboard;
}

void UiOverlay::discardFrame() {
  if (frameOpen_) ImGui::EndFrame();
  frameOpen_ = false;
}

void UiOverlay::record(const vk::raii::CommandBuffer& cmd, std::uint32_t index) {
  ImGui::Render();
  frameOpen_ = false;
  if (generation_ != swapchain_->generation()) makeFramebuffers();
  const vk::Extent2D extent = swapchain_->extent();
  cmd.beginRenderPass(vk::RenderPassBeginInfo{.renderPass = *renderPass_,
                                              .framebuffer = *framebuffers_.at(index),
                                              .renderArea = {{0, 0}, extent}},
                      vk::SubpassContents::eInline);
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), *cmd);
  cmd.endRenderPass();
}

} // namespace obscura::window
