// offscreen_target.h — the viewer's frames without a window system (FrameTarget,
// window/frame_target.h), for `view --offscreen`: no GLFW, no surface, no swapchain, no panel, so
// it runs where there is no display (GPU machines, CI). The input is the script's alone; the
// drawable is the render's size (a script's clicks are in render pixels); a frame is presented
// nowhere, and its bytes are read back only for a screenshot. A script's "close" ends the run;
// resize, minimize and restore have no window to act on (view_command refuses them up front).
#pragma once
#include "window/frame_target.h"

namespace obscura::window {

class OffscreenTarget final : public FrameTarget {
public:
  gpu::ContextOptions contextOptions(gpu::ContextOptions device) const override { return device; }
  void attach(const gpu::Context&, std::uint32_t width, std::uint32_t height, bool) override {
    size_ = {static_cast<int>(width), static_cast<int>(height)};
  }
  void detach() override {}

  InputState& input() override { return input_; }
  void pollEvents(double) override {}
  bool shouldClose() const override { return closed_; }
  void requestClose() override { closed_ = true; }
  std::array<int, 2> drawableSize() const override { return size_; }
  void applyWindowEvent(const ScriptEvent& event) override;

  UiOverlay* overlay() override { return nullptr; }
  bool presents() const override { return false; }
  bool present(const std::vector<std::uint32_t>&, UiOverlay*, std::vector<std::uint32_t>*, vk::Extent2D*) override {
    return false;
  }

private:
  InputState input_;
  std::array<int, 2> size_{0, 0};
  bool closed_ = false;
};

} // namespace obscura::window
