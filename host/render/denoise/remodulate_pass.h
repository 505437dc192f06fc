// remodulate_pass.h — the filtered terms times the albedo, plus emission and specular
// (denoise_remodulate.comp): the denoised linear image before its edges are resolved (EdgePass).
#pragma once
#include "gpu/kernel.h"
#include "render/denoise/atrous_pass.h"
#include "render/denoise/denoise_frame.h"

namespace obscura::render {

class RemodulatePass {
public:
  explicit RemodulatePass(const gpu::Context& context);
  void bind(std::uint32_t parity, const DenoiseFrame& frame);
  // From `source` (the a-trous output, or the temporal pass's with no iteration) with guide[parity].
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, FilterSource source,
              const DenoiseFrame& frame) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
