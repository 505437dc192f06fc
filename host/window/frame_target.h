// frame_target.h — where the viewer's frame loop (window/viewer.h) gets its input and puts its
// frames. The loop is the same for both targets; only this differs:
//   - WindowTarget (window/window_target.h): a GLFW window, a Vulkan surface and swapchain, the
//     ImGui panel; each frame is presented, input comes from the person (and the script);
//   - OffscreenTarget (window/offscreen_target.h): no window system at all (no DISPLAY needed);
//     input comes from the script alone, nothing is presented, and the frame's bytes are read
//     back only when a screenshot asks for them. For `view --offscreen`: benchmarks and tests
//     of the frame loop on machines without a display.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"
#include "window/event_script.h"
#include "window/glfw_window.h"

namespace obscura::window {

class UiOverlay;

class FrameTarget {
public:
  virtual ~FrameTarget() = default;

  // The device options the target needs on top of the user's (a window: the surface's instance
  // extensions and a queue that can draw the panel).
  virtual gpu::ContextOptions contextOptions(gpu::ContextOptions device) const = 0;
  // Makes what needs the device (a window: surface, swapchain, presenter, panel) for frames of
  // `width` x `height`; `panel`: the panel was asked for.
  virtual void attach(const gpu::Context& context, std::uint32_t width, std::uint32_t height, bool panel) = 0;
  // Lets go of what attach() made, while the device is still there (before the context goes).
  virtual void detach() = 0;

  virtual InputState& input() = 0;
  // Gathers the frame's input; may wait up to `waitSeconds` for some (a window while idle).
  virtual void pollEvents(double waitSeconds) = 0;
  virtual bool shouldClose() const = 0;
  virtual void requestClose() = 0;
  // The drawable's size in pixels (0 x 0 while minimised): what clicks are relative to.
  virtual std::array<int, 2> drawableSize() const = 0;
  // A script's "window" event (resize, minimize, restore, close).
  virtual void applyWindowEvent(const ScriptEvent& event) = 0;

  // The panel, or null when there is none (not asked for, or offscreen).
  virtual UiOverlay* overlay() = 0;
  // Whether frames are shown: then the loop hands every frame's display bytes to present().
  virtual bool presents() const = 0;
  // Shows `rgba` (the render's size) with `overlay` over it when given; false when nothing was
  // shown (minimised, swapchain made again). With `capture`, the image as presented (panel
  // included) at the drawable's size is written there.
  virtual bool present(const std::vector<std::uint32_t>& rgba, UiOverlay* overlay,
                       std::vector<std::uint32_t>* capture, vk::Extent2D* captureExtent) = 0;
};

} // namespace obscura::window
