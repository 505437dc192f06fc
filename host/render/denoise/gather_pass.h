// gather_pass.h — the denoiser's input from each band of the renderer's frame (denoise_gather.comp):
// guide, demodulated direct and ambient terms, sample counts, and the unfiltered rest.
#pragma once
#include "gpu/kernel.h"
#include "render/denoise/denoise_frame.h"
#include "render/frame/obscurance_frame.h"

namespace obscura::render {

class GatherPass {
public:
  GatherPass(const gpu::Context& context, std::uint32_t bands);
  // Binds band `band` of `source` to `target`'s guide[parity] (and its other inputs).
  void bind(std::uint32_t band, std::uint32_t parity, const ObscuranceFrame& source, const DenoiseFrame& target);
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, std::uint32_t parity,
              const ObscuranceFrame& source) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
