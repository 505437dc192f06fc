#include "render/denoise/remodulate_pass.h"

#include "denoise_remodulate.spv.h"

namespace obscura::render {

RemodulatePass::RemodulatePass(const gpu::Context& context)
    : kernel_(context, gpu::storageKernelDesc("denoise.remodulate", kSpirv_denoise_remodulate, gpu::kRemodulateBindingCount,
                                              0, {gpu::kBindingRemodulateGuide, gpu::kBindingRemodulateIllum},
                                              2 * kFilterSources)) {}

void RemodulatePass::bind(std::uint32_t parity, const DenoiseFrame& frame) {
  const gpu::TexelBuffer* sources[kFilterSources] = {&frame.integrated[parity], &frame.filtered[0], &frame.filtered[1]};
  for (std::uint32_t s = 0; s < kFilterSources; ++s) {
    const std::uint32_t set = filterSourceSet(parity, static_cast<FilterSource>(s));
    kernel_.bind(gpu::kBindingDenoiseParams, frame.params, set);
    kernel_.bind(gpu::kBindingRemodulateGuide, frame.guide[parity], set);
    kernel_.bind(gpu::kBindingRemodulateIllum, *sources[s], set);
    kernel_.bind(gpu::kBindingRemodulateEmission, frame.emission, set);
    kernel_.bind(gpu::kBindingRemodulateOut, frame.remodulated, set);
  }
}

void RemodulatePass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, FilterSource source,
                            const DenoiseFrame& frame) const {
  kernel_.dispatch(cmd, gpu::groupsFor(frame.pixels(), gpu::kWorkgroupSize1D), 1, 1, gpu::kNoPush, filterSourceSet(parity, source));
}

} // namespace obscura::render
