// swapchain.cpp — see swapchain.h.
#include "window/swapchain.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::window {

Swapchain::Swapchain(const gpu::Context& context, const vk::raii::SurfaceKHR& surface)
    : context_(&context), surface_(&surface) {
  const auto& physical = context.physicalDevice();
  if (!physical.getSurfaceSupportKHR(context.queueFamily(), *surface))
    throw DeviceError(fmt::format("view: {} cannot present to this window", context.info().name));
  const auto formats = physical.getSurfaceFormatsKHR(*surface);
  for (vk::Format wanted : {vk::Format::eB8G8R8A8Unorm, vk::Format::eR8G8B8A8Unorm})
    for (const auto& f : formats)
      if (format_ == vk::Format::eUndefined && f.format == wanted &&
          f.colorSpace == vk::ColorSpaceKHR::eSrgbNonlinear) {
        format_ = f.format;
        colorSpace_ = f.colorSpace;
      }
  if (format_ == vk::Format::eUndefined)
    throw DeviceError(fmt::format("view: the window offers no 8-bit UNORM format on {}", context.info().name));
  const auto modes = physical.getSurfacePresentModesKHR(*surface);
  for (vk::PresentModeKHR wanted : {vk::PresentModeKHR::eImmediate, vk::PresentModeKHR::eMailbox}) {
    if (std::find(modes.begin(), modes.end(), wanted) != modes.end()) {
      presentMode_ = wanted;
      break;
    }
  }
}

void Swapchain::recreate(std::uint32_t width, std::uint32_t height) {
  context_->device().waitIdle();
  const auto caps = context_->physicalDevice().getSurfaceCapabilitiesKHR(**surface_);
  vk::Extent2D extent = caps.currentExtent;
  if (extent.width == 0xFFFFFFFFu) {
    extent.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  const vk::ImageUsageFlags usage = vk::ImageUsageFlagBits::eColorAttachment |
                                    vk::ImageUsageFlagBits::eTransferDst | vk::ImageUsageFlagBits::eTransferSrc;
  if ((caps.supportedUsageFlags & usage) != usage)
    throw DeviceError("view: the window's images cannot be copied to and from (transfer usage)");
  std::uint32_t count = std::max(caps.minImageCount + 1, 2u);
  if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);

  views_.clear();
  vk::SwapchainCreateInfoKHR info{.surface = **surface_,
                                  .minImageCount = count,
                                  .imageFormat = format_,
                                  .imageColorSpace = colorSpace_,
                                  .imageExtent = extent,
                                  .imageArrayLayers = 1,
                                  .imageUsage = usage,
                                  .imageSharingMode = vk::SharingMode::eExclusive,
                                  .preTransform = caps.currentTransform,
                                  .compositeAlpha = vk::CompositeAlphaFlagBitsKHR::eOpaque,
                                  .presentMode = presentMode_,
                                  .clipped = VK_TRUE,
                                  .oldSwapchain = *swapchain_};
  if (!(caps.supportedCompositeAlpha & vk::CompositeAlphaFlagBitsKHR::eOpaque))
    info.compositeAlpha = vk::CompositeAlphaFlagBitsKHR::eInherit;
  vk::raii::SwapchainKHR next(context_->device(), info);
  swapchain_ = std::move(next);
  extent_ = extent;
  images_ = swapchain_.getImages();
  for (vk::Image image : images_) {
    views_.emplace_back(context_->device(),
                        vk::ImageViewCreateInfo{.image = image,
                                                .viewType = vk::ImageViewType::e2D,
                                                .format = format_,
                                                .subresourceRange = {vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1}});
  }
  ++generation_;
}

} // namespace obscura::window
