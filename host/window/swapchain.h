// swapchain.h — the images the window shows, made again when the window changes size.
//
// The format is 8-bit UNORM (B8G8R8A8 or R8G8B8A8): the renderer's display bytes are already
// sRGB-encoded by tonemap.comp, so an _SRGB swapchain would encode them twice. The present mode
// prefers IMMEDIATE, then MAILBOX, then FIFO: progressive rendering shows every sample as soon as
// it is done, and the frame rate measured is the renderer's, not the display's.
#pragma once
#include <cstdint>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

namespace obscura::window {

class Swapchain {
public:
  Swapchain(const gpu::Context& context, const vk::raii::SurfaceKHR& surface);

  // (Re)makes the images for a drawable of `width` x `height` (the surface's current extent wins
  // where it has one). Waits for the device first.
  void recreate(std::uint32_t width, std::uint32_t height);

  vk::Format format() const { return format_; }
  vk::Extent2D extent() const { return extent_; }
  std::size_t imageCount() const { return images_.size(); }
  vk::Image image(std::size_t i) const { return images_[i]; }
  const vk::raii::ImageView& view(std::size_t i) const { return views_[i]; }
  const vk::raii::SwapchainKHR& handle() const { return swapchain_; }
  // Incremented by every recreate(), so what depends on the images (framebuffers) knows to follow.
  std::uint64_t generation() const { return generation_; }

private:
  const gpu::Context* context_;
  const vk::raii::SurfaceKHR* surface_;
  vk::Format format_ = vk::Format::eUndefined;
  vk::ColorSpaceKHR colorSpace_ = vk::ColorSpaceKHR::eSrgbNonlinear;
  vk::PresentModeKHR presentMode_ = vk::PresentModeKHR::eFifo;
  vk::Extent2D extent_{0, 0};
  vk::raii::SwapchainKHR swapchain_ = nullptr;
  std::vector<vk::Image> images_;
  std::vector<vk::raii::ImageView> views_;
  std::uint64_t generation_ = 0;
};

} // namespace obscura::window
