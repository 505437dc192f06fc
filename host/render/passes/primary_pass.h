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

  // Which sample a dispatch draws: `index` in the frame's sample sequence (seeds, sub-pixel
  // position); the accumulation started at sample `first` (0 but for a farm's part), which
  // restarts the accumulators, so each pixel's count is index + 1 - first.
  struct Sample {
    std::uint32_t index = 0;
    std::uint32_t first = 0;
  };
  // Records sample `sample` of band `band`. `flags`:
  // kPrimaryFlagGBufferOnly makes the G-buffer again and accumulates nothing; kPrimaryFlagNoAovs
  // skips the AOV accumulators the frame does not keep. With kPrimaryFlagDirtyOnly, only the pixels
  // of `dirtyOf`'s dirty list for the band run (an indirect dispatch).
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              const gpu::GpuCamera& camera, Sample sample, std::uint32_t seed, std::uint32_t lights,
              std::uint32_t flags, const ObscuranceFrame* dirtyOf = nullptr) const;

private:
  // The variant for a dispatch's flags: with the AOV accumulators and/or the emission rays compiled
  // in (kSpecConstantPrimaryAovs, kSpecConstantEmissionRays) only where the flags ask for them.
  const gpu::Kernel& kernelFor(std::uint32_t flags) const;

  // Indexed by (AOVs ? 1 : 0) | (emission rays ? 2 : 0); each compiled on its first dispatch.
  std::array<gpu::Kernel, 4> kernels_;
};

} // namespace obscura::render
