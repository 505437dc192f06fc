// pass_bench.h — the renderer's side of `bench-rays --passes` and `--frame`: real frames of the
// obscurance renderer, timed per pass by its GPU timestamps and counted by its own ray counters,
// so a regression in any pass (or in what a pass does around its rays) shows beside the
// traversal's rate on the same scene.
#pragma once
#include <cstdint>
#include <vector>

#include "bench/frame_rays.h"
#include "bvh/bvh.h"
#include "gpu/context.h"
#include "render/aovs.h"
#include "scene/scene.h"

namespace obscura::bench {

// The obscurance-only frame (`work`) traced by the primary and obscurance passes: no shadow ray,
// no specular path, grey W (no colour bleeding: R(Q) is shading, not rays), primary AOVs off.
struct ObscuraFrameResult {
  double bestMs = 0.0, medianMs = 0.0; // GPU ms of primary + obscurance, best and median repeat
  double bestPrimaryMs = 0.0, bestObscuranceMs = 0.0; // the passes of the best repeat
  double bestCpuMs = 0.0;              // least process CPU time of one repeat's iterate()
  std::uint64_t primaryRays = 0, obscuranceRays = 0; // the renderer's counters (one repeat)
  std::vector<float> obscurance;       // the composed W per pixel, rows top to bottom
};
ObscuraFrameResult runObscuraFrame(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                   const scene::Camera& camera, const ObscuranceFrameWork& work, int repeats);

// The paper's budget (ObscuranceSettings' defaults: 8 spp, 5 shadow and 5 obscurance rays per
// hit, specular paths on glossy surfaces, default dMax) at width x height, rendered as `render -o
// out.png --spp 8` renders it (the combined image only, composed and tonemapped); the stats of the
// repeat with the least GPU time, after one warm-up sample.
render::RenderStats renderPaperBudget(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                      const scene::Camera& camera, std::uint32_t width, std::uint32_t height,
                                      int repeats);

} // namespace obscura::bench
