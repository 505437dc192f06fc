#include "render/passes/light_mix_pass.h"

#include <cmath>

#include "lightmix.spv.h"

namespace obscura::render {

LightMixPass::LightMixPass(const gpu::Context& context, std::uint32_t bands)
    : kernel_(context, gpu::storageKernelDesc("lightmix", kSpirv_lightmix, gpu::kLightMixBindingCount,
                                              sizeof(gpu::LightMixPush), {gpu::kBindingLightMixResolved}, bands)) {}

void LightMixPass::bind(std::uint32_t band, const ObscuranceFrame& frame, const gpu::Buffer& emissions) {
  kernel_.bind(gpu::kBindingLightMixResolved, frame.band(band).resolved, band);
  kernel_.bind(gpu::kBindingLightMixEmissions, emissions, band);
  kernel_.bind(gpu::kBindingLightMixOutput, frame.band(band).display, band);
}

void LightMixPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                          std::uint32_t lights, std::uint32_t slots, const glm::vec3& ambientIntensity,
                          float exposureStops) const {
  const gpu::LightMixPush push{.width = layout.width, .rows = layout.bands[band].rows, .lightCount = lights,
                               .lightSlots = slots, .ambient = ambientIntensity,
                               .exposureScale = std::exp2(exposureStops)};
  const std::uint64_t quads = (layout.bandPixels(band) + gpu::kResolvedPixelAlign - 1) / gpu::kResolvedPixelAlign;
  kernel_.dispatch(cmd, gpu::groupsFor(quads, gpu::kWorkgroupSize1D), 1, 1, push, band);
}

} // namespace obscura::render
