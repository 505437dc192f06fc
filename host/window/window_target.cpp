// window_target.cpp — see window_target.h.
#include "window/window_target.h"

namespace obscura::window {

WindowTarget::WindowTarget(int width, int height, const std::string& title) : window_(width, height, title) {}

WindowTarget::~WindowTarget() { detach(); }

gpu::ContextOptions WindowTarget::contextOptions(gpu::ContextOptions options) const {
  options.instanceExtensions = GlfwWindow::requiredInstanceExtensions();
  // The panel draws with a graphics pipeline and the frame is blitted: the queue must do graphics.
  // Presentation to the surface itself is checked once the surface exists (Swapchain).
  options.canPresent = [](const vk::raii::PhysicalDevice& device, std::uint32_t family) {
    return static_cast<bool>(device.getQueueFamilyProperties()[family].queueFlags & vk::QueueFlagBits::eGraphics);
  };
  return options;
}

void WindowTarget::attach(const gpu::Context& context, std::uint32_t width, std::uint32_t height, bool panel) {
  surface_ = window_.createSurface(context.instance());
  swapchain_ = std::make_unique<Swapchain>(context, surface_);
  presenter_ = std::make_unique<FramePresenter>(context, *swapchain_, width, height);
  swapchain_->recreate(width, height);
  if (panel) overlay_ = std::make_unique<UiOverlay>(context, window_, *swapchain_);
}

void WindowTarget::detach() {
  overlay_.reset();
  presenter_.reset();
  swapchain_.reset();
  surface_ = nullptr;
}

void WindowTarget::applyWindowEvent(const ScriptEvent& e) {
  if (e.text == "resize") window_.resize(static_cast<int>(e.xy[0]), static_cast<int>(e.xy[1]));
  else if (e.text == "minimize") window_.iconify();
  else if (e.text == "restore") window_.restore();
  else if (e.text == "close") window_.requestClose();
}

bool WindowTarget::present(const std::vector<std::uint32_t>& rgba, UiOverlay* overlay,
                           std::vector<std::uint32_t>* capture, vk::Extent2D* captureExtent) {
  return presenter_->present(rgba, window_.framebufferSize(), overlay, capture, captureExtent);
}

} // namespace obscura::window
