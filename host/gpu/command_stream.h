// command_stream.h — one reusable command buffer with its pool and fence, for an object that
// submits work frame after frame (a renderer, a window). Nothing is allocated per submission:
// submit() resets the buffer, records, submits and waits.
#pragma once
#include <functional>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

namespace obscura::gpu {

class CommandStream {
public:
  explicit CommandStream(const Context& context);

  // Records into the stream's command buffer, submits it and waits for the device. Device loss
  // and out-of-memory become obscura::DeviceError (as Context::submitAndWait).
  void submit(const std::function<void(const vk::raii::CommandBuffer&)>& record);

private:
  const Context* context_;
  vk::raii::CommandPool pool_ = nullptr;
  vk::raii::CommandBuffer buffer_ = nullptr;
  vk::raii::Fence fence_ = nullptr;
};

} // namespace obscura::gpu
