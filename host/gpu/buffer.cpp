#include "gpu/buffer.h"

#include <atomic>
#include <cstring>
#include <optional>

#include <fmt/core.h>

#include "core/error.h"

namespace obscura::gpu {
namespace {
constexpr vk::BufferUsageFlags kTransfer =
    vk::BufferUsageFlagBits::eTransferSrc | vk::BufferUsageFlagBits::eTransferDst;
std::atomic<std::uint64_t> liveBufferBytes{0};
} // namespace

std::uint64_t bufferBytesInUse() { return liveBufferBytes.load(); }

LiveBytes::LiveBytes(vk::DeviceSize bytes) : bytes_(bytes) { liveBufferBytes += bytes; }
LiveBytes& LiveBytes::operator=(LiveBytes&& other) noexcept {
  if (this != &other) {
    liveBufferBytes -= bytes_;
    bytes_ = std::exchange(other.bytes_, 0);
  }
  return *this;
}
LiveBytes::~LiveBytes() { liveBufferBytes -= bytes_; }

Buffer::Buffer(const Context& context, vk::DeviceSize size, vk::BufferUsageFlags usage,
               const std::string& name, Residence residence)
    : size_(size), name_(name) {
  if (size == 0) size = 16; // Vulkan forbids empty buffers; an empty scene still binds one.
  try {
    buffer_ = context.device().createBuffer({.size = size, .usage = usage | kTransfer});
    auto requirements = buffer_.getMemoryRequirements();
    // Where the CPU can read the memory as fast as its own (host-cached: lavapipe's only memory
    // type, integrated GPUs' shared memory), buffers are mapped and copied directly. Otherwise a
    // device buffer takes plain device-local memory and its transfers go through a staging
    // buffer: a discrete GPU's host-visible device memory (the PCIe BAR) is uncached for CPU
    // reads (a 256 MB download took minutes on an H200) and, without resizable BAR, only 256 MB.
    constexpr auto kHost = vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent;
    constexpr auto kHostCached = kHost | vk::MemoryPropertyFlagBits::eHostCached;
    std::uint32_t type =
        residence == Residence::Device
            ? context.findMemoryType(requirements.memoryTypeBits, vk::MemoryPropertyFlagBits::eDeviceLocal, kHostCached)
            : context.findMemoryType(requirements.memoryTypeBits, kHost, kHostCached);
    memory_ = context.device().allocateMemory(
        {.allocationSize = requirements.size, .memoryTypeIndex = type});
    liveBytes_ = LiveBytes(requirements.size);
    buffer_.bindMemory(*memory_, 0);
    auto flags = context.memoryTypeFlags(type);
    if ((flags & kHost) == kHost) {
      mapped_ = memory_.mapMemory(0, VK_WHOLE_SIZE);
      hostCached_ = bool(flags & vk::MemoryPropertyFlagBits::eHostCached);
    }
  } catch (const vk::OutOfDeviceMemoryError&) {
    throw DeviceError(fmt::format("out of device memory: buffer '{}' needs {:.1f} MiB", name,
                                  static_cast<double>(size) / (1024.0 * 1024.0)));
  } catch (const vk::OutOfHostMemoryError&) {
    throw DeviceError(fmt::format("out of host memory: buffer '{}' needs {:.1f} MiB", name,
                                  static_cast<double>(size) / (1024.0 * 1024.0)));
  }
  context.setName(buffer_, name);
}

void Buffer::upload(const Context& context, const void* data, vk::DeviceSize size,
                    vk::DeviceSize offset) {
  if (size == 0) return;
  if (offset + size > size_)
    throw std::logic_error(fmt::format("upload of {} bytes at {} overflows buffer '{}' ({} bytes)",
                                       size, offset, name_, size_));
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + offset, data, size);
    return;
  }
  Buffer staging(context, size, {}, name_ + ".staging", Residence::Host);
  staging.upload(context, data, size);
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    cmd.copyBuffer(staging.handle(), *buffer_, vk::BufferCopy{.srcOffset = 0, .dstOffset = offset, .size = size});
  });
}

void Buffer::download(const Context& context, void* data, vk::DeviceSize size,
                      vk::DeviceSize offset) const {
  if (size == 0) return;
  if (offset + size > size_)
    throw std::logic_error(fmt::format("download of {} bytes at {} overflows buffer '{}'", size,
                                       offset, name_));
  if (mapped_ && hostCached_) {
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, size);
    return;
  }
  Buffer staging(context, size, {}, name_ + ".staging", Residence::Host);
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    cmd.copyBuffer(*buffer_, staging.handle(), vk::BufferCopy{.srcOffset = offset, .dstOffset = 0, .size = size});
  });
  staging.download(context, data, size);
}

void UploadBatch::add(Buffer& destination, const void* data, vk::DeviceSize size) {
  if (size == 0) return;
  if (size > destination.size())
    throw std::logic_error(fmt::format("upload of {} bytes overflows buffer '{}' ({} bytes)", size,
                                       destination.name(), destination.size()));
  if (destination.mapped()) {
    destination.upload(*context_, data, size);
    return;
  }
  const auto at = static_cast<vk::DeviceSize>(staged_.size());
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  staged_.insert(staged_.end(), bytes, bytes + size);
  copies_.push_back({destination.handle(), at, size});
}

void UploadBatch::submit() {
  if (copies_.empty()) return;
  // Small uploads go inline in the command buffer (vkCmdUpdateBuffer: at most 65,536 bytes, whole
  // words), with no staging memory to allocate; larger ones through one staging buffer.
  constexpr vk::DeviceSize kInline = 65536;
  vk::DeviceSize stagedBytes = 0;
  for (const Copy& c : copies_)
    if (c.size > kInline || c.size % 4 != 0) stagedBytes += c.size;
  std::optional<Buffer> staging;
  if (stagedBytes > 0) {
    staging.emplace(*context_, staged_.size(), vk::BufferUsageFlags{}, "upload_batch.staging", Residence::Host);
    staging->upload(*context_, staged_.data(), staged_.size());
  }
  context_->submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    for (const Copy& c : copies_) {
      if (c.size <= kInline && c.size % 4 == 0)
        cmd.updateBuffer<std::uint8_t>(
            c.destination, 0, vk::ArrayProxy<const std::uint8_t>(static_cast<std::uint32_t>(c.size), staged_.data() + c.at));
      else
        cmd.copyBuffer(staging->handle(), c.destination, vk::BufferCopy{.srcOffset = c.at, .dstOffset = 0, .size = c.size});
    }
  });
  copies_.clear();
  staged_.clear();
}

void Buffer::fill(const Context& context, std::uint32_t value) {
  context.submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    cmd.fillBuffer(*buffer_, 0, VK_WHOLE_SIZE, value);
  });
}

TexelBuffer::TexelBuffer(const Context& context, vk::DeviceSize size, vk::Format format,
                         vk::BufferUsageFlags extraUsage, const std::string& name)
    : buffer_(context, size, vk::BufferUsageFlagBits::eUniformTexelBuffer | extraUsage, name) {
  view_ = context.device().createBufferView({.buffer = buffer_.handle(), .format = format, .offset = 0,
                                             .range = VK_WHOLE_SIZE});
}

TexelBuffer::TexelBuffer(const Context& context, const void* data, vk::DeviceSize size,
                         const std::string& name, vk::BufferUsageFlags extraUsage)
    : buffer_(context, size, vk::BufferUsageFlagBits::eUniformTexelBuffer | extraUsage, name) {
  buffer_.upload(context, data, size);
  view_ = context.device().createBufferView({.buffer = buffer_.handle(),
                                             .format = vk::Format::eR32G32B32A32Sfloat,
                                             .offset = 0,
                                             .range = VK_WHOLE_SIZE});
}

} // namespace obscura::gpu
