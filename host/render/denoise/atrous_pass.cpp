#include "render/denoise/atrous_pass.h"

#include "denoise_atrous.spv.h"

namespace obscura::render {

FilterSource filterSourceAfter(std::uint32_t iterations) {
  if (iterations == 0) return FilterSource::Integrated;
  return iterations % 2 == 1 ? FilterSource::Filtered0 : FilterSource::Filtered1;
}

AtrousPass::AtrousPass(const gpu::Context& context)
    : kernel_(context, gpu::storageKernelDesc("denoise.atrous", kSpirv_denoise_atrous, gpu::kAtrousBindingCount,
                                              sizeof(gpu::DenoisePush), {gpu::kBindingAtrousGuide, gpu::kBindingAtrousIn},
                                              2 * kFilterSources)) {}

void AtrousPass::bind(std::uint32_t parity, const DenoiseFrame& frame) {
  struct Route {
    FilterSource source;
    const gpu::TexelBuffer* in;
    const gpu::TexelBuffer* out;
  };
  const Route routes[kFilterSources] = {{FilterSource::Integrated, &frame.integrated[parity], &frame.filtered[0]},
                                  {FilterSource::Filtered0, &frame.filtered[0], &frame.filtered[1]},
                                  {FilterSource::Filtered1, &frame.filtered[1], &frame.filtered[0]}};
  for (const Route& r : routes) {
    const std::uint32_t set = filterSourceSet(parity, r.source);
    kernel_.bind(gpu::kBindingDenoiseParams, frame.params, set);
    kernel_.bind(gpu::kBindingAtrousGuide, frame.guide[parity], set);
    kernel_.bind(gpu::kBindingAtrousIn, *r.in, set);
    kernel_.bind(gpu::kBindingAtrousOut, r.out->buffer(), set);
  }
}

void AtrousPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, std::uint32_t iteration,
                        const DenoiseFrame& frame) const {
  const gpu::DenoisePush push{.firstRow = 0u, .rows = 0u, .composedSlots = 0u, .step = 1u << iteration};
  dispatchImage(kernel_, cmd, frame, push, filterSourceSet(parity, filterSourceAfter(iteration)));
}

} // namespace obscura::render
