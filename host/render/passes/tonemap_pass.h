// tonemap_pass.h — one composed AOV to display bytes (tonemap.comp): exposure, sRGB, RGBA8.
#pragma once
#include "gpu/kernel.h"
#include "shared/host_device.h"
#include "render/frame/obscurance_frame.h"

namespace obscura::render {

class TonemapPass {
public:
  TonemapPass(const gpu::Context& context, std::uint32_t bands);

  void bind(std::uint32_t band, const ObscuranceFrame& frame);
  // Any composed image (vec4 per pixel and slot) into any display buffer (the denoiser's).
  void bind(std::uint32_t band, const gpu::Buffer& composed, const gpu::Buffer& display);
  // `slot` is a kCompose* slot; `channels` 1 shows its .x grey.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout, std::uint32_t slot,
              std::uint32_t channels, float exposureStops, std::uint32_t slots) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
