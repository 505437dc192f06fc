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
#include <utility>
#include <vector>

#include <vulkan/vulkan_raii.hpp>

#include "gpu/context.h"

namespace obscura::gpu {

// Device memory held by this process's buffers now, all contexts together: what a program that
// makes and drops renderers (the Python API's sessions, a test of leaks) checks comes back.
std::uint64_t bufferBytesInUse();

// A buffer's share of bufferBytesInUse(), counted while it lives and moved with it.
class LiveBytes {
public:
  LiveBytes() = default;
  explicit LiveBytes(vk::DeviceSize bytes);
  LiveBytes(LiveBytes&& other) noexcept : bytes_(std::exchange(other.bytes_, 0)) {}
  LiveBytes& operator=(LiveBytes&& other) noexcept;
  LiveBytes(const LiveBytes&) = delete;
  LiveBytes& operator=(const LiveBytes&) = delete;
  ~LiveBytes();

private:
  vk::DeviceSize bytes_ = 0;
};

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
  // Whether the CPU writes it directly (its memory is mapped), without a staging copy.
  bool mapped() const { return mapped_ != nullptr; }
  const std::string& name() const { return name_; }
  explicit operator bool() const { return size_ != 0; }

private:
  // Declaration order is creation order; members are destroyed bottom-up (buffer before memory).
  vk::raii::DeviceMemory memory_ = nullptr;
  LiveBytes liveBytes_; // memory_'s size in bufferBytesInUse()
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
  Buffer& buffer() { return buffer_; }
  // New contents of the same size; the view stays valid.
  void upload(const Context& context, const void* data, vk::DeviceSize size, vk::DeviceSize offset = 0) {
    buffer_.upload(context, data, size, offset);
  }
  vk::BufferView view() const { return *view_; }

private:
  Buffer buffer_;
  vk::raii::BufferView view_ = nullptr;
};

// Several uploads in one submission through one staging buffer. An edit that refills a few small
// tables (an added light: its lights, emitters, tree, scales, bounds) otherwise waited for a
// staging allocation and a submission per table, ~2 ms each on an H200's host. Mapped
// destinations (lavapipe) are written at once.
class UploadBatch {
public:
  explicit UploadBatch(const Context& context) : context_(&context) {}
  UploadBatch(const UploadBatch&) = delete;
  UploadBatch& operator=(const UploadBatch&) = delete;
  // Buffers mapped are written at once; the others wait for submit(), which must come before the
  // batch goes (and before their contents are read).
  void add(Buffer& destination, const void* data, vk::DeviceSize size);
  template <typename T>
  void add(Buffer& destination, const std::vector<T>& data) {
    add(destination, data.data(), data.size() * sizeof(T));
  }
  void submit();

private:
  struct Copy {
    vk::Buffer destination;
    vk::DeviceSize at; // in the staged bytes
    vk::DeviceSize size;
  };
  const Context* context_;
  std::vector<std::uint8_t> staged_;
  std::vector<Copy> copies_;
};

// `data` into `buffer` (a storage buffer) through `uploads`, keeping the buffer where it holds
// them and else making it twice as large as they need (a table that grows by one row an edit,
// such as a light added, is not made anew each time); at least one element long. True when it
// made a new buffer: the kernels that read it must be bound again.
template <typename T>
bool refillArray(const Context& context, UploadBatch& uploads, Buffer& buffer, const std::vector<T>& data,
                 const std::string& name) {
  const std::size_t count = std::max<std::size_t>(data.size(), 1);
  bool made = false;
  if (buffer.size() < count * sizeof(T)) {
    buffer = Buffer(context, 2 * count * sizeof(T), vk::BufferUsageFlagBits::eStorageBuffer, name);
    made = true;
  }
  if (data.empty()) uploads.add(buffer, std::vector<T>(1));
  else uploads.add(buffer, data);
  return made;
}

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
