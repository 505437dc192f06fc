#include "render/denoise/reproject_pass.h"

#include "denoise_reproject.spv.h"

namespace obscura::render {

ReprojectPass::ReprojectPass(const gpu::Context& context)
    : kernel_(context, gpu::storageKernelDesc("denoise.reproject", kSpirv_denoise_reproject, gpu::kReprojectBindingCount, 0,
                                              {gpu::kBindingReprojectGuide, gpu::kBindingReprojectHistoryGuide,
                                               gpu::kBindingReprojectHistory},
                                              2)) {}

void ReprojectPass::bind(std::uint32_t parity, const DenoiseFrame& frame) {
  const std::uint32_t history = 1 - parity;
  kernel_.bind(gpu::kBindingDenoiseParams, frame.params, parity);
  kernel_.bind(gpu::kBindingReprojectGuide, frame.guide[parity], parity);
  kernel_.bind(gpu::kBindingReprojectHistoryGuide, frame.guide[history], parity);
  kernel_.bind(gpu::kBindingReprojectHistory, frame.integrated[history], parity);
  kernel_.bind(gpu::kBindingReprojectCarry, frame.carry, parity);
}

void ReprojectPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, const DenoiseFrame& frame) const {
  dispatchImage(kernel_, cmd, frame, gpu::kNoPush, parity);
}

} // namespace obscura::render
