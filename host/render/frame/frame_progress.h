// frame_progress.h — what a frame's sums hold besides their values: how many samples, which
// sample's primary hits the G-buffer holds, the camera rays traced for them, and which of the
// resolved transport (resolve.comp, for light edits) is stale. The frame owns it
// (ObscuranceFrame::progress); the renderer's sample loop and edits advance it.
#pragma once
#include <algorithm>
#include <cstdint>

namespace obscura::render {

struct FrameProgress {
  static constexpr std::uint32_t kNoSample = ~0u;

  std::uint32_t samples = 0;
  // The sample whose primary hits the G-buffer holds at every pixel (kNoSample: none, or mixed),
  // so that an added light's rays start from it without a primary pass.
  std::uint32_t gbufferSample = kNoSample;
  std::uint64_t primaryRays = 0; // camera rays traced into the sums (and G-buffers remade)

  // The resolved transport is current for lights before resolveFrom (and the ambient unless
  // resolveAmbient); a new sample makes all of it stale, an added light only itself.
  std::uint32_t resolveFrom = 0;
  bool resolveAmbient = true;
  // A geometry edit's retrace left only the pixels of the dirty lists stale (the rest is current).
  bool resolveDirty = false;

  void markResolveStale(std::uint32_t fromLight, bool ambient) {
    resolveFrom = std::min(resolveFrom, fromLight);
    resolveAmbient = resolveAmbient || ambient;
  }
  // Everything is resolved for `lights` lights.
  void resolved(std::uint32_t lights) {
    resolveFrom = lights;
    resolveAmbient = false;
    resolveDirty = false;
  }
  // The frame starts over: no sample, nothing resolved.
  void restart() { *this = FrameProgress{}; }
};

} // namespace obscura::render
