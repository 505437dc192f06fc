// frame_presenter.cpp — see frame_presenter.h.
#include "window/frame_presenter.h"

#include <algorithm>
#include <limits>

#include <fmt/format.h>

#include "core/error.h"
#include "window/ui_overlay.h"

namespace obscura::window {
namespace {

constexpr vk::ImageSubresourceRange kColour{vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1};

void barrier(const vk::raii::CommandBuffer& cmd, vk::Image image, vk::ImageLayout from, vk::ImageLayout to,
             vk::AccessFlags srcAccess, vk::AccessFlags dstAccess, vk::PipelineStageFlags srcStage,
             vk::PipelineStageFlags dstStage) {
  vk::ImageMemoryBarrier b{.srcAccessMask = srcAccess,
                           .dstAccessMask = dstAccess,
                           .oldLayout = from,
                           .newLayout = to,
                           .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                           .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
                           .image = image,
                           .subresourceRange = kColour};
  cmd.pipelineBarrier(srcStage, dstStage, {}, {}, {}, b);
}

} // namespace

std::array<vk::Offset3D, 2> fitToDrawable(std::uint32_t width, std::uint32_t height, vk::Extent2D drawable) {
  const double scale = std::min(double(drawable.width) / width, double(drawable.height) / height);
  const auto w = std::max<std::int32_t>(1, static_cast<std::int32_t>(width * scale + 0.5));
  const auto h = std::max<std::int32_t>(1, static_cast<std::int32_t>(height * scale + 0.5));
  const std::int32_t x = (static_cast<std::int32_t>(drawable.width) - w) / 2;
  const std::int32_t y = (static_cast<std::int32_t>(drawable.height) - h) / 2;
  return {vk::Offset3D{x, y, 0}, vk::Offset3D{x + w, y + h, 1}};
}


FramePresenter::FramePresenter(const gpu::Context& context, Swapchain& swapchain, std::uint32_t width,
                               std::uint32_t height)
    : context_(&context), swapchain_(&swapchain), width_(width), height_(height) {
  const auto& device = context.device();
  pool_ = vk::raii::CommandPool(device, vk::CommandPoolCreateInfo{
                                            .flags = vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                            .queueFamilyIndex = context.queueFamily()});
  cmd_ = std::move(vk::raii::CommandBuffers(device, vk::CommandBufferAllocateInfo{
                                                        .commandPool = *pool_,
                                                        .level = vk::CommandBufferLevel::ePrimary,
                                                        .commandBufferCount = 1})
                       .front());
  inFlight_ = vk::raii::Fence(device, vk::FenceCreateInfo{.flags = vk::FenceCreateFlagBits::eSignaled});
  acquired_ = vk::raii::Semaphore(device, vk::SemaphoreCreateInfo{});
  makeImage();
}

FramePresenter::~FramePresenter() { context_->device().waitIdle(); }

void FramePresenter::makeImage() {
  const auto& device = context_->device();
  staging_ = gpu::Buffer(*context_, vk::DeviceSize(width_) * height_ * 4, vk::BufferUsageFlagBits::eTransferSrc,
                         "window.staging", gpu::Residence::Host);
  image_ = nullptr;
  imageMemory_ = nullptr;
  image_ = vk::raii::Image(device, vk::ImageCreateInfo{.imageType = vk::ImageType::e2D,
                                                       .format = vk::Format::eR8G8B8A8Unorm,
                                                       .extent = {width_, height_, 1},
                                                       .mipLevels = 1,
                                                       .arrayLayers = 1,
                                                       .samples = vk::SampleCountFlagBits::e1,
                                                       .tiling = vk::ImageTiling::eOptimal,
                                                       .usage = vk::ImageUsageFlagBits::eTransferDst |
                                                                vk::ImageUsageFlagBits::eTransferSrc,
                                                       .initialLayout = vk::ImageLayout::eUndefined});
  const auto requirements = image_.getMemoryRequirements();
  imageMemory_ = vk::raii::DeviceMemory(
      device, vk::MemoryAllocateInfo{.allocationSize = requirements.size,
                                     .memoryTypeIndex = context_->findMemoryType(
                                         requirements.memoryTypeBits, vk::MemoryPropertyFlagBits::eDeviceLocal)});
  image_.bindMemory(*imageMemory_, 0);
  context_->setName(image_, "window.frame");
}

bool FramePresenter::present(const std::vector<std::uint32_t>& rgba, std::array<int, 2> drawable, UiOverlay* overlay,
                             std::vector<std::uint32_t>* capture, vk::Extent2D* captureExtent) {
  if (drawable[0] <= 0 || drawable[1] <= 0) return false; // minimised: nothing to show
  if (rgba.size() != std::size_t(width_) * height_)
    throw std::logic_error("FramePresenter::present: the frame is not of the render's size");
  if (stale_ || drawable != lastDrawable_) {
    swapchain_->recreate(static_cast<std::uint32_t>(drawable[0]), static_cast<std::uint32_t>(drawable[1]));
    rendered_.clear();
    for (std::size_t i = 0; i < swapchain_->imageCount(); ++i)
      rendered_.emplace_back(context_->device(), vk::SemaphoreCreateInfo{});
    lastDrawable_ = drawable;
    stale_ = false;
  }
  const auto& device = context_->device();
  if (device.waitForFences(*inFlight_, VK_TRUE, std::numeric_limits<std::uint64_t>::max()) != vk::Result::eSuccess)
    throw DeviceError("view: waiting for the last frame failed");

  std::uint32_t index = 0;
  try {
    auto [result, acquiredIndex] =
        swapchain_->handle().acquireNextImage(std::numeric_limits<std::uint64_t>::max(), *acquired_);
    if (result == vk::Result::eSuboptimalKHR) stale_ = true; // still usable; made again next frame
    index = acquiredIndex;
  } catch (const vk::OutOfDateKHRError&) {
    stale_ = true;
    return false;
  }
  device.resetFences(*inFlight_);
  staging_.upload(*context_, rgba);

  cmd_.reset();
  cmd_.begin(vk::CommandBufferBeginInfo{.flags = vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
  record(cmd_, index, overlay, capture != nullptr);
  cmd_.end();
  const vk::PipelineStageFlags waitStage = vk::PipelineStageFlagBits::eTransfer;
  vk::CommandBuffer cmd = *cmd_;
  vk::Semaphore wait = *acquired_, signal = *rendered_[index];
  context_->queue().submit(vk::SubmitInfo{.waitSemaphoreCount = 1,
                                          .pWaitSemaphores = &wait,
                                          .pWaitDstStageMask = &waitStage,
                                          .commandBufferCount = 1,
                                          .pCommandBuffers = &cmd,
                                          .signalSemaphoreCount = 1,
                                          .pSignalSemaphores = &signal},
                           *inFlight_);
  if (capture) {
    if (device.waitForFences(*inFlight_, VK_TRUE, std::numeric_limits<std::uint64_t>::max()) != vk::Result::eSuccess)
      throw DeviceError("view: waiting for the screenshot failed");
    const vk::Extent2D extent = swapchain_->extent();
    std::vector<std::uint32_t> bytes(std::size_t(extent.width) * extent.height);
    readback_.download(*context_, bytes.data(), bytes.size() * 4);
    if (swapchain_->format() == vk::Format::eB8G8R8A8Unorm)
      for (auto& p : bytes) p = (p & 0xFF00FF00u) | ((p >> 16) & 0xFFu) | ((p & 0xFFu) << 16);
    *capture = std::move(bytes);
    if (captureExtent) *captureExtent = extent;
  }
  vk::SwapchainKHR chain = *swapchain_->handle();
  try {
    vk::Result result = context_->queue().presentKHR(vk::PresentInfoKHR{.waitSemaphoreCount = 1,
                                                                         .pWaitSemaphores = &signal,
                                                                         .swapchainCount = 1,
                                                                         .pSwapchains = &chain,
                                                                         .pImageIndices = &index});
    if (result == vk::Result::eSuboptimalKHR) stale_ = true;
  } catch (const vk::OutOfDateKHRError&) {
    stale_ = true;
  }
  return true;
}

void FramePresenter::record(const vk::raii::CommandBuffer& cmd, std::uint32_t index, UiOverlay* overlay, bool capture) {
  using Stage = vk::PipelineStageFlagBits;
  using Access = vk::AccessFlagBits;
  using Layout = vk::ImageLayout;
  const vk::Image target = swapchain_->image(index);
  const vk::Extent2D extent = swapchain_->extent();

  // The frame: staging buffer -> the render-sized image.
  barrier(cmd, *image_, Layout::eUndefined, Layout::eTransferDstOptimal, {}, Access::eTransferWrite, Stage::eTopOfPipe,
          Stage::eTransfer);
  cmd.copyBufferToImage(staging_.handle(), *image_, Layout::eTransferDstOptimal,
                        vk::BufferImageCopy{.imageSubresource = {vk::ImageAspectFlagBits::eColor, 0, 0, 1},
                                            .imageExtent = {width_, height_, 1}});
  barrier(cmd, *image_, Layout::eTransferDstOptimal, Layout::eTransferSrcOptimal, Access::eTransferWrite,
          Access::eTransferRead, Stage::eTransfer, Stage::eTransfer);

  // The swapchain image: bars cleared, the frame blitted to fit (the blit converts RGBA to BGRA).
  barrier(cmd, target, Layout::eUndefined, Layout::eTransferDstOptimal, {}, Access::eTransferWrite, Stage::eTransfer,
          Stage::eTransfer);
  cmd.clearColorImage(target, Layout::eTransferDstOptimal, vk::ClearColorValue(std::array<float, 4>{0.08f, 0.08f, 0.09f, 1.0f}),
                      kColour);
  barrier(cmd, target, Layout::eTransferDstOptimal, Layout::eTransferDstOptimal, Access::eTransferWrite,
          Access::eTransferWrite, Stage::eTransfer, Stage::eTransfer);
  const auto dst = fitToDrawable(width_, height_, extent);
  const bool exact = dst[1].x - dst[0].x == static_cast<std::int32_t>(width_) &&
                     dst[1].y - dst[0].y == static_cast<std::int32_t>(height_);
  cmd.blitImage(*image_, Layout::eTransferSrcOptimal, target, Layout::eTransferDstOptimal,
                vk::ImageBlit{.srcSubresource = {vk::ImageAspectFlagBits::eColor, 0, 0, 1},
                              .srcOffsets = std::array<vk::Offset3D, 2>{vk::Offset3D{0, 0, 0},
                                                                        vk::Offset3D{static_cast<std::int32_t>(width_),
                                                                                     static_cast<std::int32_t>(height_), 1}},
                              .dstSubresource = {vk::ImageAspectFlagBits::eColor, 0, 0, 1},
                              .dstOffsets = dst},
                exact ? vk::Filter::eNearest : vk::Filter::eLinear);

  Layout layout = Layout::eTransferDstOptimal;
  if (overlay) {
    barrier(cmd, target, layout, Layout::eColorAttachmentOptimal, Access::eTransferWrite,
            Access::eColorAttachmentRead | Access::eColorAttachmentWrite, Stage::eTransfer,
            Stage::eColorAttachmentOutput);
    overlay->record(cmd, index);
    layout = Layout::eColorAttachmentOptimal;
  }
  const Access written = overlay ? Access::eColorAttachmentWrite : Access::eTransferWrite;
  const vk::PipelineStageFlags writtenAt = overlay ? Stage::eColorAttachmentOutput : Stage::eTransfer;
  if (capture) {
    const vk::DeviceSize bytes = vk::DeviceSize(extent.width) * extent.height * 4;
    if (!readback_ || readback_.size() != bytes)
      readback_ = gpu::Buffer(*context_, bytes, vk::BufferUsageFlagBits::eTransferDst, "window.screenshot",
                              gpu::Residence::Host);
    barrier(cmd, target, layout, Layout::eTransferSrcOptimal, written, Access::eTransferRead, writtenAt, Stage::eTransfer);
    cmd.copyImageToBuffer(target, Layout::eTransferSrcOptimal, readback_.handle(),
                          vk::BufferImageCopy{.imageSubresource = {vk::ImageAspectFlagBits::eColor, 0, 0, 1},
                                              .imageExtent = {extent.width, extent.height, 1}});
    barrier(cmd, target, Layout::eTransferSrcOptimal, Layout::ePresentSrcKHR, Access::eTransferRead, {}, Stage::eTransfer,
            Stage::eBottomOfPipe);
  } else {
    barrier(cmd, target, layout, Layout::ePresentSrcKHR, written, {}, writtenAt, Stage::eBottomOfPipe);
  }
}

} // namespace obscura::window
