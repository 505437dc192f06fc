// buffer.h — a Vulkan buffer and its memory as one RAII value.
//
// Buffers live in device-local memory. When that memory is also host-visible (lavapipe, GPUs
// with resizable BAR) uploads and readbacks are plain memcpy; otherwise they go through a
// temporary staging buffer.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

namespace obscura::gpu {

// Where a buffer lives: device-local (the default), or host-visible for staging (buffer.cpp says
// which memory types each takes).
enum class Residence { Device, Host };

class Buffer {
public:
  Buffer() = default;
  // `name` labels the buffer in validation messages ("<pass>.<role>").
  Buffer(const Context& context, vk::DeviceSize size, vk::BufferUsageFlags usage,
         const std::string& name, Residence residence = Residence::Device);

  void upload(const Context& context, const void* data, vk::DeviceSize size, vk::DeviceSize offset = 0);
  template <typename T>
  void upload(const Context& context, std::span<const T> data) {
    upload(context, data.data(), data.size_bytes());
  }
  template <typename T>
  void upload(const Context& context, const std::vector<T>& data) {
    upload(context, data.data(), data.size() * sizeof(T));
  }
  void download(const Context& context, void* data, vk::DeviceSize size, vk::DeviceSize offset = 0) const;
  template <typename T>
  std::vector<T> download(const Context& context) const {
    std::vector<T> out(size_ / sizeof(T));
    download(context, out.data(), out.size() * sizeof(T));
    return out;
  }
  void fill(const Context& context, std::uint32_t value);

  vk::Buffer handle() const { return *buffer_; }
  vk::DeviceSize size() const { return size_; }
  const std::string& name() const { return name_; }
  explicit operator bool() const { return size_ != 0; }

private:
  // Declaration order is creation order; members are destroyed bottom-up (buffer before memory).
  vk::raii::DeviceMemory memory_ = nullptr;
  vk::raii::Buffer buffer_ = nullptr;
  vk::DeviceSize size_ = 0;
  void* mapped_ = nullptr; // persistent mapping when the memory is host-visible
  bool hostCached_ = false; // ...and cached, so that the CPU reads it at memory speed
  std::string name_;
};

// A buffer with a texel view, read through uniform texel buffers (or, where its usage allows,
// written through storage texel buffers) where lavapipe moves texels as vectors instead of one
// scalar access per lane and word (docs/ARCHITECTURE.md): the BVH (RGBA32F texels), the frame's
// G-buffer and Kahan sums, the resolved transport of light edits (RGBA32UI: four pixels per texel).
class TexelBuffer {
public:
  TexelBuffer() = default;
  // RGBA32F texels of `data`; `extraUsage` besides the texel view (e.g. storage, to bind it as an SSBO too).
  TexelBuffer(const Context& context, const void* data, vk::DeviceSize size, const std::string& name,
              vk::BufferUsageFlags extraUsage = {});
  // `size` bytes of `format` texels, uninitialised; `extraUsage` (e.g. storage, for a pass that
  // writes them) besides the texel view.
  TexelBuffer(const Context& context, vk::DeviceSize size, vk::Format format, vk::BufferUsageFlags extraUsage,
              const std::string& name);
  const Buffer& buffer() const { return buffer_; }
  // New contents of the same size; the view stays valid.
  void upload(const Context& context, const void* data, vk::DeviceSize size, vk::DeviceSize offset = 0) {
    buffer_.upload(context, data, size, offset);
  }
  vk::BufferView view() const { return *view_; }

private:
  Buffer buffer_;
  vk::raii::BufferView view_ = nullptr;
};

// A storage buffer holding `data`, at least one element long: Vulkan has no empty buffers, and
// a scene without lights still binds its light buffers.
template <typename T>
Buffer uploadArray(const Context& context, const std::vector<T>& data, const std::string& name) {
  Buffer buffer(context, std::max<std::size_t>(data.size(), 1) * sizeof(T), vk::BufferUsageFlagBits::eStorageBuffer,
                name);
  if (!data.empty()) buffer.upload(context, data);
  return buffer;
}

} // namespace obscura::gpu
