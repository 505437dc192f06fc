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
  // (kSpecConstantReflectors, lib/obscurance.glsl): that kernel takes the dispatches of a sample
  // with ShadeSample::secondaryReflectors, and the others leave that code out.
  bool reflectors = false;
  // The shader has a variant without colour bleeding (kSpecConstantGreyObscurance,
  // lib/obscurance.glsl): it takes the dispatches without ShadeSample::colourBleeding that
  // neither probe nor gather reflectors.
  bool grey = false;
  // The shader shades one light alone when specialised for it (kSpecConstantPerLight): that kernel
  // takes the dispatches of one light that do not probe (ShadeDispatch::perLightVariant).
  bool perLight = false;
  // The shader's probing kernel has a variant that tests the frame's kept rays instead of drawing
  // them (kSpecConstantReplayRays, lib/kept_rays.glsl): it takes the probing dispatches with
  // ShadeDispatch::keptRays that do not shade one light alone.
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

  // Band `band` of `frame`: every pixel, or the band's dirty list (dispatch.dirtyOnly, an
  // indirect dispatch). The kernel follows from the dispatch: the probing one to probe (following
  // the kept rays where it may), the reflectors' where the render gathers them, the per-light one
  // for one light, the grey one without colour bleeding.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const ObscuranceFrame& frame,
              const ShadeSample& sample, const ShadeDispatch& dispatch) const {
    const FrameLayout& layout = frame.layout();
    const gpu::ShadePush push = packShadePush(sample, dispatch, layout, band);
    const bool reflectors = reflectors_ && sample.secondaryReflectors;
    // A geometry edit retraces every pixel while the reflectors are on (they are marked anew), so
    // nothing probes with them; the probing kernel has no reflectors' code.
    if (dispatch.probe && reflectors) throw std::logic_error("PixelShadingPass: no probing variant with secondary reflectors");
    // Only the per-light variant (and the probe) shades one light alone: the plain kernel has no
    // code for it.
    const bool perLight = dispatch.perLightVariant();
    if (perLight && (!perLight_ || reflectors)) throw std::logic_error("PixelShadingPass: no per-light variant");
    const bool replay = probeReplay_ && dispatch.probe && dispatch.keptRays && !dispatch.oneLight();
    const bool grey = grey_ && !dispatch.probe && !reflectors && !perLight && !sample.colourBleeding;
    const gpu::Kernel& kernel = replay ? *probeReplay_ : dispatch.probe ? probe_ : reflectors ? *reflectors_
                              : perLight ? *perLight_ : grey ? *grey_ : kernel_;
    if (dispatch.dirtyOnly) {
      kernel.dispatchIndirect(cmd, frame.band(band).dirty, frame.dirtyListOffset(band), push, band);
      return;
    }
    kernel.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                    gpu::groupsFor(layout.bands[band].rows, gpu::kWorkgroupSizeY), 1, push, band);
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
