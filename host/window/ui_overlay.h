// ui_overlay.h — Dear ImGui drawn over the rendered image: its GLFW input backend and its Vulkan
// draw backend (Debian's libimgui-dev), a render pass that loads the swapchain image the frame was
// blitted into, and one framebuffer per swapchain image, made again with the swapchain.
#pragma once
#include <cstdint>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"
#include "window/glfw_window.h"
#include "window/swapchain.h"

namespace obscura::window {

class UiOverlay {
public:
  UiOverlay(const gpu::Context& context, GlfwWindow& window, const Swapchain& swapchain);
  ~UiOverlay();
  UiOverlay(const UiOverlay&) = delete;
  UiOverlay& operator=(const UiOverlay&) = delete;

  // Starts an ImGui frame; tells `input` whether the panel has the mouse or the keyboard.
  void beginFrame(InputState& input);
  // Ends the ImGui frame and records its draw into swapchain image `index`, which is in
  // COLOR_ATTACHMENT_OPTIMAL layout and stays so.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t index);
  // Ends a frame that will not be drawn (the window is minimised).
  void discardFrame();

private:
  void makeFramebuffers();

  const gpu::Context* context_;
  const Swapchain* swapchain_;
  vk::raii::DescriptorPool pool_ = nullptr;
  vk::raii::RenderPass renderPass_ = nullptr;
  std::vector<vk::raii::Framebuffer> framebuffers_;
  std::uint64_t generation_ = 0;
  bool frameOpen_ = false;
};

} // namespace obscura::window
