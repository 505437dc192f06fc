// specular_pass.h — specular paths from glossy primary hits (specular_queue.comp compacts the
// glossy pixels of a band into a queue and sizes an indirect dispatch of specular.comp), gathering
// direct light and obscurance at their vertices [RTO §4.1 step 4]. specular.comp runs one vertex
// depth per dispatch and queues the paths that go on for the next (a wavefront).
#pragma once
#include "render/passes/shading_inputs.h"

namespace obscura::render {

class SpecularPass {
public:
  SpecularPass(const gpu::Context& context, const ShadingSpecialisation& s);

  void bind(std::uint32_t band, const ShadingInputs& in);
  // Compiles now the kernels only edits dispatch (else compiled at their first dispatch): those
  // that replay the kept lobe hits where the frame keeps them, else those that trace.
  void compileEditKernels(bool keptHits) const {
    (keptHits ? probeReplay_ : probe_).compile();
    (keptHits ? perLightReplay_ : perLight_).compile();
  }
  // Clears band `band`'s queue, fills it and dispatches the paths, one dispatch per depth
  // (barriers included). A per-light or probing dispatch with kept rays follows the kept hits
  // (the .replay kernels).
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const ObscuranceFrame& frame,
              const ShadeSample& sample, const ShadeDispatch& dispatch) const;

private:
  gpu::Kernel queue_;
  gpu::Kernel paths_;
  gpu::Kernel probe_;    // paths_'s probing variant (ShadeDispatch::probe)
  gpu::Kernel perLight_; // paths_'s variant for an added light alone (kSpecConstantPerLight)
  // probe_ and perLight_ following the frame's kept lobe hits (kSpecConstantReplayRays)
  gpu::Kernel probeReplay_, perLightReplay_;
};

} // namespace obscura::render
