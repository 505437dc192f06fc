// atrous_pass.h — one edge-aware a-trous wavelet iteration (denoise_atrous.comp).
#pragma once
#include "gpu/kernel.h"
#include "render/denoise/denoise_frame.h"

namespace obscura::render {

// Where an iteration reads its terms: the temporal pass's output, or either half of the ping-pong.
enum class FilterSource : std::uint32_t { Integrated = 0, Filtered0 = 1, Filtered1 = 2 };
// The source of the iteration after `iterations` ones (Integrated after none).
FilterSource filterSourceAfter(std::uint32_t iterations);
// Passes that read a filter source keep one descriptor set per (parity, source).
inline constexpr std::uint32_t kFilterSources = 3;
inline std::uint32_t filterSourceSet(std::uint32_t parity, FilterSource source) {
  return parity * kFilterSources + static_cast<std::uint32_t>(source);
}

class AtrousPass {
public:
  explicit AtrousPass(const gpu::Context& context);
  void bind(std::uint32_t parity, const DenoiseFrame& frame);
  // Iteration `iteration` (taps 2^iteration pixels apart) with guide[parity]: from
  // filterSourceAfter(iteration) into the other half of the ping-pong.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t parity, std::uint32_t iteration,
              const DenoiseFrame& frame) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
