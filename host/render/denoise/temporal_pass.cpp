#include "render/denoise/temporal_pass.h"

#include "denoise_temporal.spv.h"

namespace obscura::render {

TemporalPass::TemporalPass(const gpu::Context& context)
    : kernel_(context, gpu::storageKernelDesc("denoise.temporal", kSpirv_denoise_temporal, gpu::kTemporalBindingCount, 0,
                                              {gpu::kBindingTemporalGuide, gpu::kBindingTemporalNoisy}, 2)) {}

void TemporalPass::bind(std::uint32_t parity, const DenoiseFrame& frame) {
  kernel_.bind(gpu::kBindingDenoiseParams, frame.params, parity);
  kernel_.bind(gpu::kBindingTemporalGuide, frame.guide[parity], parity);
  kernel_.bind(gpu::kBindingTemporalNoisy, frame.noisy, parity);
  kernel_.bind(gpu::kBindingTemporalCarry, frame.carry, parity);
  kernel_.bind(gpu::kBindingTemporalOut, frame.integrated[parity].buffer(), parity);
}

void TemporalPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, const DenoiseFrame& frame) const {
  dispatchImage(kernel_, cmd, frame, gpu::kNoPush, parity);
}

} // namespace obscura::render
