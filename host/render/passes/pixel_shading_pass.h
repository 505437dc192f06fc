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
      : kernel_(context, shadingKernelDesc(name, spirv, bands)) {}

  void bind(std::uint32_t band, const ShadingInputs& in) { bindShadingInputs(kernel_, band, in); }

  // Every pixel of the band; or, with `dirtyOf` (and kShadeFlagDirtyOnly in the push), only the
  // pixels of that frame's dirty list for the band, dispatched indirectly.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              const gpu::ShadePush& push, const ObscuranceFrame* dirtyOf = nullptr) const {
    const gpu::ShadePush p = forBand(push, layout, band);
    if (dirtyOf != nullptr) {
      kernel_.dispatchIndirect(cmd, dirtyOf->band(band).dirty, dirtyOf->dirtyListOffset(band), &p, band);
      return;
    }
    kernel_.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                     gpu::groupsFor(layout.bands[band].rows, gpu::kWorkgroupSizeY), 1, &p, band);
  }

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
