#include "render/passes/resolve_pass.h"

#include "resolve.spv.h"

namespace obscura::render {

ResolvePass::ResolvePass(const gpu::Context& context, std::uint32_t bands)
    : kernel_(context, gpu::storageKernelDesc("resolve", kSpirv_resolve, gpu::kResolveBindingCount, sizeof(gpu::ResolvePush),
                                              {gpu::kBindingResolveBasis, gpu::kBindingResolveAmbient,
                                               gpu::kBindingResolveEmissionBasis, gpu::kBindingResolveSpecularBasis,
                                               gpu::kBindingResolveSpecularAmbient},
                                              bands)) {}

void ResolvePass::bind(std::uint32_t band, const ObscuranceFrame& frame) {
  const auto& b = frame.band(band);
  kernel_.bind(gpu::kBindingResolveBasis, b.basis, band);
  kernel_.bind(gpu::kBindingResolveEmissionBasis, b.emissionBasis, band);
  kernel_.bind(gpu::kBindingResolveSpecularBasis, b.specularBasis, band);
  kernel_.bind(gpu::kBindingResolveAmbient, b.ambient, band);
  kernel_.bind(gpu::kBindingResolveSpecularAmbient, b.specularAmbient, band);
  kernel_.bind(gpu::kBindingResolveOutput, b.resolved.buffer(), band);
  kernel_.bind(gpu::kBindingResolveSampleCounts, b.sampleCounts, band);
  kernel_.bind(gpu::kBindingResolveDirty, b.dirty, band);
  frame_ = &frame;
}

void ResolvePass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                         std::uint32_t lights, std::uint32_t slots, bool specular,
                         std::uint32_t firstLight, bool ambient, bool dirtyOnly) const {
  const gpu::ResolvePush push{.width = layout.width, .rows = layout.bands[band].rows, .lightCount = lights,
                              .specular = specular ? 1u : 0u, .firstLight = firstLight, .ambient = ambient ? 1u : 0u,
                              .lightSlots = slots, .dirtyOnly = dirtyOnly ? 1u : 0u};
  if (dirtyOnly) {
    kernel_.dispatchIndirect(cmd, frame_->band(band).dirty, frame_->dirtyListOffset(band), push, band);
    return;
  }
  kernel_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, band);
}

} // namespace obscura::render
