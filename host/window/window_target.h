// window_target.h — the viewer's frames in a window (FrameTarget, window/frame_target.h): GLFW,
// a Vulkan surface and swapchain, FramePresenter and the ImGui panel (UiOverlay). Needs a window
// system; DeviceError without one.
#pragma once
#include <memory>
#include <optional>
#include <string>

#include "window/frame_presenter.h"
#include "window/frame_target.h"
#include "window/glfw_window.h"
#include "window/swapchain.h"
#include "window/ui_overlay.h"

namespace obscura::window {

class WindowTarget final : public FrameTarget {
public:
  // Opens the window (the device is made after, with contextOptions()).
  WindowTarget(int width, int height, const std::string& title);
  ~WindowTarget() override;

  gpu::ContextOptions contextOptions(gpu::ContextOptions device) const override;
  void attach(const gpu::Context& context, std::uint32_t width, std::uint32_t height, bool panel) override;
  void detach() override;

  InputState& input() override { return window_.input(); }
  void pollEvents(double waitSeconds) override { window_.pollEvents(waitSeconds); }
  bool shouldClose() const override { return window_.shouldClose(); }
  void requestClose() override { window_.requestClose(); }
  std::array<int, 2> drawableSize() const override { return window_.framebufferSize(); }
  void applyWindowEvent(const ScriptEvent& event) override;

  UiOverlay* overlay() override { return overlay_.get(); }
  bool presents() const override { return true; }
  bool present(const std::vector<std::uint32_t>& rgba, UiOverlay* overlay, std::vector<std::uint32_t>* capture,
               vk::Extent2D* captureExtent) override;

private:
  GlfwWindow window_;
  // Made by attach(), in this order, and let go of in the reverse.
  vk::raii::SurfaceKHR surface_ = nullptr;
  std::unique_ptr<Swapchain> swapchain_;
  std::unique_ptr<FramePresenter> presenter_;
  std::unique_ptr<UiOverlay> overlay_;
};

} // namespace obscura::window
