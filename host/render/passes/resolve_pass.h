// resolve_pass.h — a band's Kahan sums to the shared-exponent (RGB9E5) per-light transport that light edits
// read (resolve.comp).
#pragma once
#include "gpu/kernel.h"
#include "render/frame/obscurance_frame.h"
#include "shared/host_device.h"

namespace obscura::render {

class ResolvePass {
public:
  ResolvePass(const gpu::Context& context, std::uint32_t bands);
  void bind(std::uint32_t band, const ObscuranceFrame& frame);
  // Every pixel of the band; with `dirtyOnly`, those of the frame's dirty list (dispatched indirectly).
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              std::uint32_t lights, std::uint32_t slots, bool specular,
              std::uint32_t firstLight, bool ambient, bool dirtyOnly = false) const;

private:
  gpu::Kernel kernel_;
  const ObscuranceFrame* frame_ = nullptr; // whose dirty lists a dirty-only resolve reads (bind)
};

} // namespace obscura::render
