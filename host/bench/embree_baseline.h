// embree_baseline.h — Intel Embree 3 tracing exactly the bench-rays rays in the same process, so
// `obscura bench-rays --baseline embree` reports a ratio that machine load affects on both sides.
// Compiled only when CMake finds Embree 3 (OBSCURA_HAVE_EMBREE).
#pragma once
#include <cstdint>
#include <vector>

#include "shared/host_device.h"
#include "scene/scene.h"

namespace obscura::bench {

struct EmbreeSetResult {
  double bestMs = 0.0, medianMs = 0.0;
  double bestCpuMs = 0.0;   // least process CPU time (all threads) of one repeat
  double hitFraction = 0.0; // closest: rays that hit; shadow: rays occluded
};

struct EmbreeBaselineResult {
  double buildSeconds = 0.0; // rtcCommitScene (BVH build), RTC_BUILD_QUALITY_MEDIUM (the default)
  unsigned threads = 0;
  EmbreeSetResult closest, shadow;
};

// Builds an Embree scene from the scene's triangles and times rtcIntersect1 (closest) and
// rtcOccluded1 (shadow) on the given rays, `threads` std::threads over ray chunks (0 = hardware
// concurrency), best and median of `repeats` runs. Throws DeviceError on an Embree error.
EmbreeBaselineResult runEmbreeBaseline(const scene::Scene& scene, const std::vector<gpu::GpuRay>& closestRays,
                                       const std::vector<gpu::GpuRay>& shadowRays, int repeats,
                                       unsigned threads = 0);

} // namespace obscura::bench
