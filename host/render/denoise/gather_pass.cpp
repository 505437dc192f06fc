#include "render/denoise/gather_pass.h"

#include "denoise_gather.spv.h"

namespace obscura::render {

GatherPass::GatherPass(const gpu::Context& context, std::uint32_t bands)
    : kernel_(context, gpu::storageKernelDesc("denoise.gather", kSpirv_denoise_gather, gpu::kGatherBindingCount,
                                              sizeof(gpu::DenoisePush), {}, 2 * bands)) {}

void GatherPass::bind(std::uint32_t band, std::uint32_t parity, const ObscuranceFrame& source,
                      const DenoiseFrame& target) {
  const std::uint32_t set = 2 * band + parity;
  const auto& b = source.band(band);
  kernel_.bind(gpu::kBindingDenoiseParams, target.params, set);
  kernel_.bind(gpu::kBindingGatherComposed, b.composed, set);
  kernel_.bind(gpu::kBindingGatherAovs, b.aovs, set);
  kernel_.bind(gpu::kBindingGatherSampleCounts, b.sampleCounts, set);
  kernel_.bind(gpu::kBindingGatherGuide, target.guide[parity].buffer(), set);
  kernel_.bind(gpu::kBindingGatherIllum, target.noisy.buffer(), set);
  kernel_.bind(gpu::kBindingGatherEmission, target.emission, set);
}

void GatherPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, std::uint32_t parity,
                        const ObscuranceFrame& source) const {
  const FrameLayout& layout = source.layout();
  const gpu::DenoisePush push{.firstRow = layout.bands[band].firstRow, .rows = layout.bands[band].rows,
                              .composedSlots = source.contents().composedSlots, .step = 0u};
  kernel_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, 2 * band + parity);
}

} // namespace obscura::render
