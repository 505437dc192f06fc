// status_counters.h — the counters the tracing shaders add to (binding kBindingStatus: rays per
// pass, truncated traversals, dirty pixels; host_device.h kStatus*). A renderer keeps its frame's
// own; SceneBuffers keeps one for users that trace without a renderer (bench-rays, tests).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/context.h"

namespace obscura::render {

class StatusCounters {
public:
  StatusCounters() = default;
  StatusCounters(const gpu::Context& context, const std::string& name); // starts at zero

  std::vector<std::uint32_t> words() const; // kStatusWords values
  void reset();
  const gpu::Buffer& buffer() const { return buffer_; }

private:
  const gpu::Context* context_ = nullptr;
  gpu::Buffer buffer_;
};

} // namespace obscura::render
