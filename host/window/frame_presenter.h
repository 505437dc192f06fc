// frame_presenter.h — puts a rendered frame on the window: the display bytes (RGBA8, sRGB-encoded,
// what ObscuranceRenderer::display() gives) go through a host-visible staging buffer into an image
// of the render's size, which is blitted (scaled to fit, aspect kept, bars cleared) into the
// swapchain image; the panel is drawn over it and the image presented.
//
// One frame in flight: the renderer's own submissions already wait for the device, so a second
// frame in flight would buy nothing and cost a second staging buffer. A screenshot with the panel
// copies the presented image back before it goes to the window.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "window/swapchain.h"

namespace obscura::window {

class UiOverlay;

// Where a render of `width` x `height` is shown in a drawable: the largest rectangle of its aspect,
// centred (corners: [0] inclusive, [1] exclusive).
std::array<vk::Offset3D, 2> fitToDrawable(std::uint32_t width, std::uint32_t height, vk::Extent2D drawable);

class FramePresenter {
public:
  FramePresenter(const gpu::Context& context, Swapchain& swapchain, std::uint32_t width, std::uint32_t height);
  ~FramePresenter();

  // Shows `rgba` (width x height of the render) on a drawable of `drawable` pixels, with `overlay`
  // on top when given. Returns false when nothing was shown (minimised, or the swapchain was out of
  // date and has been made again: show the next frame). With `capture`, the image as presented
  // (panel included), RGBA8 row by row at the swapchain's size, is written there.
  bool present(const std::vector<std::uint32_t>& rgba, std::array<int, 2> drawable, UiOverlay* overlay,
               std::vector<std::uint32_t>* capture = nullptr, vk::Extent2D* captureExtent = nullptr);

private:
  void makeImage();
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t index, UiOverlay* overlay, bool capture);

  const gpu::Context* context_;
  Swapchain* swapchain_;
  std::uint32_t width_, height_;
  gpu::Buffer staging_;
  gpu::Buffer readback_;
  vk::raii::DeviceMemory imageMemory_ = nullptr;
  vk::raii::Image image_ = nullptr;
  vk::raii::CommandPool pool_ = nullptr;
  vk::raii::CommandBuffer cmd_ = nullptr;
  vk::raii::Fence inFlight_ = nullptr;
  vk::raii::Semaphore acquired_ = nullptr;
  std::vector<vk::raii::Semaphore> rendered_; // one per swapchain image (presentation holds it)
  std::array<int, 2> lastDrawable_{0, 0};
  bool stale_ = true; // the swapchain must be made (again) before the next frame
};

} // namespace obscura::window
