// pixel_shading_pass.h — a shading pass with one invocation per pixel of a band: the base of the
// shadow and obscurance passes (which differ only in their shader).
#pragma once
#include <memory>
#include <span>
#include <stdexcept>

#include "render/passes/shading_inputs.h"

namespace obscura::render {

// The specialised variants a pixel shading pass compiles beside its kernel and its probing kernel.
struct ShadingVariants {
  // The shader gathers the secondary reflectors' light when specialised for it
  // (kSpecConstantReflectors, lib/obscurance.glsl): that kernel takes the dispatches with
  // kFlagSecondaryReflectors, and the others leave that code out.
  bool reflectors = false;
  // The shader has a variant without colour bleeding (kSpecConstantGreyObscurance,
  // lib/obscurance.glsl): it takes the dispatches without kFlagBleed that neither probe nor
  // gather reflectors.
  bool grey = false;
  // The shader shades one light alone when specialised for it (kSpecConstantPerLight): that kernel
  // takes the kShadeFlagPerLight dispatches that do not probe.
  bool perLight = false;
  // The shader's probing kernel has a variant that tests the frame's kept rays instead of drawing
  // them (kSpecConstantReplayRays, lib/kept_rays.glsl): it takes the probing dispatches with
  // kShadeFlagKeptRays that do not shade one light alone.
  bool replayKeptRays = false;
};

class PixelShadingPass {
public:
  PixelShadingPass(const gpu::Context& context, const char* name, std::span<const std::uint32_t> spirv,
                   const ShadingSpecialisation& s, ShadingVariants variants = {})
      : kernel_(context, shadingKernelDesc(name, spirv, s)), probe_(context, probingKernelDesc(name, spirv, s)),
        reflectors_(variants.reflectors ? std::make_unique<gpu::Kernel>(context, reflectorKernelDesc(name, spirv, s))
                                        : nullptr),
        grey_(variants.grey ? std::make_unique<gpu::Kernel>(context, greyObscuranceKernelDesc(name, spirv, s))
                            : nullptr),
        perLight_(variants.perLight ? std::make_unique<gpu::Kernel>(context, perLightKernelDesc(name, spirv, s))
                                    : nullptr),
        probeReplay_(variants.replayKeptRays
                         ? std::make_unique<gpu::Kernel>(context, replayingKeptRaysKernelDesc(probingKernelDesc(name, spirv, s)))
                         : nullptr) {}

  void bind(std::uint32_t band, const ShadingInputs& in) {
    bindShadingInputs(kernel_, band, in);
    bindShadingInputs(probe_, band, in);
    if (reflectors_) bindShadingInputs(*reflectors_, band, in);
    if (grey_) bindShadingInputs(*grey_, band, in);
    if (perLight_) bindShadingInputs(*perLight_, band, in);
    if (probeReplay_) bindShadingInputs(*probeReplay_, band, in);
  }

  // Compiles now the kernels only edits dispatch (else compiled at their first dispatch): the probe
  // that tests the kept rays where the frame keeps them (`keptRays`), else the one that draws them.
  void compileEditKernels(bool keptRays) const {
    (keptRays && probeReplay_ ? *probeReplay_ : probe_).compile();
    if (perLight_) perLight_->compile();
  }

  // Every pixel of the band; or, with `dirtyOf` (and kShadeFlagDirtyOnly in the push), only the
  // pixels of that frame's dirty list for the band, dispatched indirectly. kShadeFlagProbe in the
  // push runs the probing kernel (over a dirty list's candidates).
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              const gpu::ShadePush& push, const ObscuranceFrame* dirtyOf = nullptr) const {
    const gpu::ShadePush p = forBand(push, layout, band);
    const bool probe = (push.band.z & gpu::kShadeFlagProbe) != 0;
    const bool reflectors = reflectors_ && (push.counts.w & gpu::kFlagSecondaryReflectors) != 0;
    // A geometry edit retraces every pixel while the reflectors are on (they are marked anew), so
    // nothing probes with them; the probing kernel has no reflectors' code.
    if (probe && reflectors) throw std::logic_error("PixelShadingPass: no probing variant with secondary reflectors");
    // Only the per-light variant (and the probe) shades one light alone: the plain kernel has no
    // code for it.
    const bool perLight = takesPerLightVariant(p);
    if (perLight && (!perLight_ || reflectors)) throw std::logic_error("PixelShadingPass: no per-light variant");
    const bool replay = probeReplay_ && probe && (push.band.z & gpu::kShadeFlagKeptRays) != 0 &&
                        (push.band.z & gpu::kShadeFlagPerLight) == 0;
    const bool grey = grey_ && !probe && !reflectors && !perLight && (push.counts.w & gpu::kFlagBleed) == 0;
    const gpu::Kernel& kernel = replay ? *probeReplay_ : probe ? probe_ : reflectors ? *reflectors_ : perLight ? *perLight_
                              : grey ? *grey_ : kernel_;
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
  std::unique_ptr<gpu::Kernel> reflectors_;
  std::unique_ptr<gpu::Kernel> grey_;
  std::unique_ptr<gpu::Kernel> perLight_;
  std::unique_ptr<gpu::Kernel> probeReplay_;
};

} // namespace obscura::render
