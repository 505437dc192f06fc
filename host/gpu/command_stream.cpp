#include "gpu/command_stream.h"

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::gpu {

CommandStream::CommandStream(const Context& context) : context_(&context) {
  const auto& device = context.device();
  pool_ = device.createCommandPool({.flags = vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                    .queueFamilyIndex = context.queueFamily()});
  vk::raii::CommandBuffers buffers(device, {.commandPool = *pool_, .level = vk::CommandBufferLevel::ePrimary,
                                            .commandBufferCount = 1});
  buffer_ = std::move(buffers.front());
  fence_ = device.createFence({});
}

void CommandStream::submit(const std::function<void(const vk::raii::CommandBuffer&)>& record) {
  const auto& device = context_->device();
  try {
    buffer_.reset();
    buffer_.begin({.flags = vk::CommandBufferUsageFlagBits::eOneTimeSubmit});
    record(buffer_);
    buffer_.end();
    vk::CommandBuffer raw = *buffer_;
    context_->queue().submit(vk::SubmitInfo{.commandBufferCount = 1, .pCommandBuffers = &raw}, *fence_);
    while (device.waitForFences(*fence_, VK_TRUE, UINT64_MAX) == vk::Result::eTimeout) {
    }
    device.resetFences(*fence_);
  } catch (const vk::DeviceLostError& e) {
    throw DeviceError(fmt::format("the Vulkan device '{}' was lost: {}", context_->info().name, e.what()));
  } catch (const vk::OutOfDeviceMemoryError& e) {
    throw DeviceError(fmt::format("out of device memory on '{}': {}", context_->info().name, e.what()));
  } catch (const vk::OutOfHostMemoryError& e) {
    throw DeviceError(fmt::format("out of host memory in the Vulkan driver: {}", e.what()));
  }
}

} // namespace obscura::gpu
