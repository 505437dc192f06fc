// reproject_pass.h — the history seen from the current camera, disocclusions rejected
// (denoise_reproject.comp).
#pragma once
#include "gpu/kernel.h"
#include "render/denoise/denoise_frame.h"

namespace obscura::render {

class ReprojectPass {
public:
  explicit ReprojectPass(const gpu::Context& context);
  // Set `parity`: the current frame's guide[parity], the history's [1 - parity], into the carry.
  void bind(std::uint32_t parity, const DenoiseFrame& frame);
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, const DenoiseFrame& frame) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
