#include "render/passes/tonemap_pass.h"

#include <cmath>

#include "tonemap.spv.h"

namespace obscura::render {

TonemapPass::TonemapPass(const gpu::Context& context, std::uint32_t bands)
    : kernel_(context, gpu::storageKernelDesc("tonemap", kSpirv_tonemap, gpu::kTonemapBindingCount, sizeof(gpu::TonemapPush), bands)) {}

void TonemapPass::bind(std::uint32_t band, const ObscuranceFrame& frame) {
  bind(band, frame.band(band).composed, frame.band(band).display);
}

void TonemapPass::bind(std::uint32_t band, const gpu::Buffer& composed, const gpu::Buffer& display) {
  kernel_.bind(gpu::kBindingTonemapInput, composed, band);
  kernel_.bind(gpu::kBindingTonemapOutput, display, band);
}

void TonemapPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                         std::uint32_t slot, std::uint32_t channels, float exposureStops,
                         std::uint32_t slots) const {
  const gpu::TonemapPush push{.width = layout.width, .rows = layout.bands[band].rows, .slot = slot,
                              .channels = channels, .exposureScale = std::exp2(exposureStops), .composedSlots = slots};
  kernel_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, band);
}

} // namespace obscura::render
