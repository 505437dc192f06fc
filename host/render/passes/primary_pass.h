// primary_pass.h — camera rays to the G-buffer, the AOV accumulators and the seen-emission basis
// M_s (primary.comp) [RTO §4.1 step 1].
#pragma once
#include <array>
#include <cstdint>

#include "gpu/kernel.h"
#include "render/frame/obscurance_frame.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/scene.h"

namespace obscura::render {

// Pinhole camera for an image of width x height. The image's aspect ratio wins over the camera's
// (the caller chooses the image size from the camera's aspect when the user gave none).
// backgroundLight: the slot of the sky a camera ray that leaves the scene sees (kInvalidIndex: none).
gpu::GpuCamera gpuCamera(const scene::Camera& camera, std::uint32_t width, std::uint32_t height,
                         std::uint32_t backgroundLight = gpu::kInvalidIndex);

class PrimaryPass {
public:
  // `scene`: what the kernels are specialised for by the scene (SceneBuffers::specialisation: the
  // compact traversal stack, the texture kinds). `hitBounds`: keep each pixel's box of hits
  // (kSpecConstantPrimaryHitBounds), which only geometry edits read.
  PrimaryPass(const gpu::Context& context, std::uint32_t bands, const SceneSpecialisation& scene,
              bool hitBounds = true);

  // Binds band `band`'s descriptor set: the scene, the frame's status counters and band buffers,
  // and the lights' render-time emission scales (which make M_s unit).
  void bind(std::uint32_t band, const SceneBuffers& scene, const ObscuranceFrame& frame,
            const gpu::Buffer& lightScales);

  // One dispatch of the primary pass, by name: PrimaryPass::record packs it into PrimaryPush.
  struct Dispatch {
    // Which sample it draws: `sample` in the frame's sample sequence (seeds, sub-pixel position);
    // the accumulation started at sample `firstSample` (0 but for a farm's part), which restarts
    // the accumulators, so each pixel's count is sample + 1 - firstSample.
    std::uint32_t sample = 0;
    std::uint32_t firstSample = 0;
    std::uint32_t seed = 1;
    std::uint32_t lights = 0;
    // Make the G-buffer of the sample again and accumulate nothing (an added light's rays, a
    // geometry edit's probes start from it).
    bool gbufferOnly = false;
    // Accumulate the primary AOVs (only where the frame keeps them).
    bool aovs = true;
    // Only the pixels of the frame's dirty list (a geometry edit's retrace), dispatched indirectly.
    bool dirtyOnly = false;
    // --emission-samples K: above 1 (and accumulating), M_s from K camera rays of their own;
    // `emissionAtEdges` (--emission-samples auto): only where an emitter's edge crosses the pixel.
    std::uint32_t emissionSamples = 1;
    bool emissionAtEdges = false;
  };
  // Records `dispatch` over band `band` of `frame`, whose whole image `camera` sees.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const ObscuranceFrame& frame,
              const gpu::GpuCamera& camera, const Dispatch& dispatch) const;

private:
  // The variant for a dispatch: with the AOV accumulators and/or the emission rays compiled in
  // (kSpecConstantPrimaryAovs, kSpecConstantEmissionRays) only where it asks for them.
  const gpu::Kernel& kernelFor(const Dispatch& dispatch) const;

  // Indexed by (AOVs ? 1 : 0) | (emission rays ? 2 : 0); each compiled on its first dispatch.
  std::array<gpu::Kernel, 4> kernels_;
};

} // namespace obscura::render
