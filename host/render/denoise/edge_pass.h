// edge_pass.h — the pixels an edge crosses, resolved from camera rays of their own
// (denoise_edges.comp): the denoised linear image. The only denoiser pass that traces the scene:
// it is specialised for the renderer's scene as its tracing passes are, and made again when an
// edit changes what that needs.
#pragma once
#include <cstdint>

#include "gpu/kernel.h"
#include "render/denoise/denoise_frame.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::render {

class ObscuranceRenderer;

class EdgePass {
public:
  EdgePass(const gpu::Context& context, const SceneSpecialisation& scene);

  // Binds the renderer's scene, status counters and light tables and the frame's buffers, with
  // guide[parity]. Called before every dispatch (a handful of descriptor writes): an edit may have
  // made the renderer's buffers anew; the kernel is made again where the scene's specialisation
  // changed.
  void bind(const ObscuranceRenderer& renderer, const DenoiseFrame& frame, std::uint32_t parity);
  // What a dispatch traces and weighs (DenoiseEdgesPush).
  struct Dispatch {
    std::uint32_t geometryRays = 0;    // camera rays where a geometric edge crosses (0: copy)
    std::uint32_t emitterRays = 0;     // where an emitter's border does
    std::uint32_t lights = 0;          // the renderer's light slots
    std::uint32_t ownEmissionRays = 1; // the renderer's emission rays per sample there
    float ambientLuminance = 0.0f;     // of the renderer's I_a: the scale of an emitter's step
  };
  void record(const vk::raii::CommandBuffer& cmd, const DenoiseFrame& frame, const Dispatch& dispatch) const;

private:
  const gpu::Context* context_;
  SceneSpecialisation scene_;
  gpu::Kernel kernel_;
};

} // namespace obscura::render
