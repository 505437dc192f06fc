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
  gpu::TonemapPush push{.frame = glm::uvec4(layout.width, layout.bands[band].rows, slot, channels),
                        .params = glm::vec4(std::exp2(exposureStops), 0.0f, 0.0f, 0.0f),
                        .slots = glm::uvec4(slots, 0u, 0u, 0u)};
  kernel_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, &push, band);
}

} // namespace obscura::render
