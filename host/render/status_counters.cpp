#include "render/status_counters.h"

#include "shared/host_device.h"

namespace obscura::render {

StatusCounters::StatusCounters(const gpu::Context& context, const std::string& name)
    : context_(&context),
      buffer_(context, gpu::kStatusWords * 4,
              vk::BufferUsageFlagBits::eStorageBuffer | vk::BufferUsageFlagBits::eTransferSrc |
                  vk::BufferUsageFlagBits::eTransferDst,
              name) {
  reset();
}

std::vector<std::uint32_t> StatusCounters::words() const {
  std::vector<std::uint32_t> out(gpu::kStatusWords);
  buffer_.download(*context_, out.data(), out.size() * 4);
  return out;
}

void StatusCounters::reset() {
  const std::vector<std::uint32_t> zeros(gpu::kStatusWords, 0u);
  buffer_.upload(*context_, zeros);
}

} // namespace obscura::render
