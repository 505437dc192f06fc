// embree_frame.h — Intel Embree 3 doing the work of an obscurance-only frame in this process:
// each pixel's camera rays of every sample (rtcIntersect1), and at each hit N_obs obscurance
// rays with tmax = dMax (rtcIntersect1: rho needs the distance), the rays of bench/frame_rays.h,
// accumulating W = mean rho(d) (the sqrt rho [RTO §3]) per pixel. `bench-rays --frame` sets it
// against Obscura's primary and obscurance passes on the same frame.
#pragma once
#include <cstdint>
#include <vector>

#include "bench/frame_rays.h"
#include "scene/scene.h"

namespace obscura::bench {

struct EmbreeFrameResult {
  double bestMs = 0.0, medianMs = 0.0; // wall time of the frame, best and median of the repeats
  double bestCpuMs = 0.0;              // least process CPU time of one repeat
  unsigned threads = 0;
  std::uint64_t primaryRays = 0;
  std::uint64_t primaryHits = 0;
  // N_obs per hit, as obscurance.comp counts them (a direction below the geometric normal is
  // counted, not traced), and the rays traced.
  std::uint64_t obscuranceRays = 0, obscuranceRaysTraced = 0;
  std::vector<float> obscurance; // W per pixel, rows top to bottom (0 where nothing is hit)
};

// Throws DeviceError on an Embree error. `threads` 0: hardware concurrency.
EmbreeFrameResult runEmbreeFrame(const scene::Scene& scene, const ObscuranceFrameWork& work, int repeats,
                                 unsigned threads = 0);

} // namespace obscura::bench
