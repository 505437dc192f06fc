#include "render/passes/specular_pass.h"

#include <algorithm>
#include <array>

#include "specular.spv.h"
#include "specular_queue.spv.h"

namespace obscura::render {

SpecularPass::SpecularPass(const gpu::Context& context, const ShadingSpecialisation& s)
    : queue_(context, shadingKernelDesc("specular.queue", kSpirv_specular_queue, s)),
      paths_(context, shadingKernelDesc("specular", kSpirv_specular, s)),
      probe_(context, probingKernelDesc("specular", kSpirv_specular, s)),
      perLight_(context, perLightKernelDesc("specular", kSpirv_specular, s)),
      probeReplay_(context, replayingKeptRaysKernelDesc(probingKernelDesc("specular", kSpirv_specular, s))),
      perLightReplay_(context, replayingKeptRaysKernelDesc(perLightKernelDesc("specular", kSpirv_specular, s))) {}

void SpecularPass::bind(std::uint32_t band, const ShadingInputs& in) {
  bindShadingInputs(queue_, band, in);
  bindShadingInputs(paths_, band, in);
  bindShadingInputs(probe_, band, in);
  bindShadingInputs(perLight_, band, in);
  bindShadingInputs(probeReplay_, band, in);
  bindShadingInputs(perLightReplay_, band, in);
}

void SpecularPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const ObscuranceFrame& frame,
                          const ShadeSample& sample, const ShadeDispatch& dispatch) const {
  // An empty queue dispatches (0, 1, 1) groups; specular_queue.comp and specular.comp raise x as
  // they append.
  static constexpr std::array<std::uint32_t, gpu::kQueueHeader> kEmptyQueue = {0u, 1u, 1u, 0u};
  const FrameLayout& layout = frame.layout();
  const gpu::Buffer& queue = frame.band(band).queue;
  const auto pixels = static_cast<std::uint32_t>(layout.bandPixels(band));
  auto clearQueue = [&](std::uint32_t depth) {
    cmd.updateBuffer<std::uint32_t>(queue.handle(), vk::DeviceSize(gpu::specularQueueBase(depth, pixels)) * 4, kEmptyQueue);
  };
  clearQueue(1);
  gpu::computeBarrier(cmd);
  queue_.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                  gpu::groupsFor(layout.bands[band].rows, gpu::kWorkgroupSizeY), 1,
                  packShadePush(sample, dispatch, layout, band), band);
  gpu::computeBarrier(cmd);
  const bool replay = dispatch.keptRays;
  const gpu::Kernel& paths = dispatch.probe              ? (replay ? probeReplay_ : probe_)
                             : dispatch.perLightVariant() ? (replay ? perLightReplay_ : perLight_)
                                                          : paths_;
  // One dispatch per vertex depth; each fills the queue of the next (specular.comp). A path
  // depth of 1 still runs depth 1, which only finishes the paths.
  const std::uint32_t lastDepth = std::max(sample.maxDepth, 2u) - 1u;
  for (std::uint32_t depth = 1; depth <= lastDepth; ++depth) {
    if (depth < lastDepth) {
      clearQueue(depth + 1);
      gpu::computeBarrier(cmd);
    }
    paths.dispatchIndirect(cmd, queue, vk::DeviceSize(gpu::specularQueueBase(depth, pixels)) * 4,
                           packShadePush(sample, dispatch, layout, band, depth), band);
    if (depth < lastDepth) gpu::computeBarrier(cmd);
  }
}

} // namespace obscura::render
