// pixel_shading_pass.h — a shading pass with one invocation per pixel of a band: the base of the
// shadow and obscurance passes (which differ only in their shader).
#pragma once
#include <span>

#include "render/passes/shading_inputs.h"

namespace obscura::render {

class PixelShadingPass {
public:
  PixelShadingPass(const gpu::Context& context, const char* name, std::span<const std::uint32_t> spirv,
                   std::uint32_t bands)
      : kernel_(context, shadingKernelDesc(name, spirv, bands)), probe_(context, probingKernelDesc(name, spirv, bands)) {}

  void bind(std::uint32_t band, const ShadingInputs& in) {
    bindShadingInputs(kernel_, band, in);
    bindShadingInputs(probe_, band, in);
  }

  // Every pixel of the band; or, with `dirtyOf` (and kShadeFlagDirtyOnly in the push), only the
  // pixels of that frame's dirty list for the band, dispatched indirectly. kShadeFlagProbe in the
  // push runs the probing kernel (over a dirty list's candidates).
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              const gpu::ShadePush& push, const ObscuranceFrame* dirtyOf = nullptr) const {
    const gpu::ShadePush p = forBand(push, layout, band);
    const gpu::Kernel& kernel = (push.band.z & gpu::kShadeFlagProbe) != 0 ? probe_ : kernel_;
    if (dirtyOf != nullptr) {
      kernel.dispatchIndirect(cmd, dirtyOf->band(band).dirty, dirtyOf->dirtyListOffset(band), &p, band);
      return;
    }
    kernel.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                     gpu::groupsFor(layout.bands[band].rows, gpu::kWorkgroupSizeY), 1, &p, band);
  }

private:
  gpu::Kernel kernel_;
  gpu::Kernel probe_;
};

} // namespace obscura::render
