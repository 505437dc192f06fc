// denoise_frame.h — the denoiser's buffers: whole-frame (gathered from the renderer's bands), by
// the layouts of shared/host_device.h ("The denoiser"). What the next frame reprojects (the guide
// and the temporally integrated terms with their sample counts) is kept in two copies: one the
// current frame writes, one the history holds; `parity` says which is which.
#pragma once
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/kernel.h"
#include "shared/host_device.h"

namespace obscura::render {

struct DenoiseFrame {
  // InputError when a whole-frame buffer (32 bytes per pixel) exceeds the device's per-buffer or
  // texel-buffer limit: the denoiser gathers the bands into one.
  DenoiseFrame(const gpu::Context& context, std::uint32_t width, std::uint32_t height);

  std::uint32_t width = 0, height = 0;
  gpu::Buffer params;                // DenoiseParams
  gpu::TexelBuffer guide[2];         // [parity]: this frame's, the history's
  // Illum buffers (two texels per pixel):
  gpu::TexelBuffer noisy;            // the gathered terms
  gpu::Buffer carry;                 // the history reprojected to this frame's camera
  gpu::TexelBuffer integrated[2];    // [parity]: the temporal pass's output, this frame's and the history's
  gpu::TexelBuffer filtered[2];      // a-trous ping-pong
  gpu::Buffer emission;              // vec4: seen emission, added back unfiltered
  gpu::Buffer remodulated;           // vec4: the filtered terms remodulated, + emission; w = samples
  gpu::Buffer combined;              // vec4: the denoised linear image (edges resolved)
  gpu::Buffer display;               // uint: RGBA8

  std::uint64_t pixels() const { return std::uint64_t(width) * height; }
};

// A dispatch of workgroups covering the frame's image in 2D (kWorkgroupSizeX x kWorkgroupSizeY),
// with `push` (or gpu::kNoPush).
template <class Push>
void dispatchImage(const gpu::Kernel& kernel, const vk::raii::CommandBuffer& cmd, const DenoiseFrame& frame,
                   const Push& push, std::uint32_t set) {
  kernel.dispatch(cmd, gpu::groupsFor(frame.width, gpu::kWorkgroupSizeX), gpu::groupsFor(frame.height, gpu::kWorkgroupSizeY),
                  1, push, set);
}

} // namespace obscura::render
