// temporal_pass.h — the current mean blended with the reprojected history by sample counts, and
// the luminance variances that steer the filter (denoise_temporal.comp).
#pragma once
#include "gpu/kernel.h"
#include "render/denoise/denoise_frame.h"

namespace obscura::render {

class TemporalPass {
public:
  explicit TemporalPass(const gpu::Context& context);
  // Set `parity`: reads guide[parity], the gathered terms and the carry; writes integrated[parity].
  void bind(std::uint32_t parity, const DenoiseFrame& frame);
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, const DenoiseFrame& frame) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
