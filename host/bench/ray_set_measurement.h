// ray_set_measurement.h — the measurement behind `obscura bench-rays`: one set of rays traced by
// a render::RayTracer, warmed up, then timed over repeats (back to back in one submission on a GPU, whose
// clocks would drop between submissions; one by one with the process CPU time on lavapipe, which
// the Embree ratio reads), with the statistics that explain a rate and the check that makes it
// honest (the hits against the CPU traversal).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "render/ray_tracer.h"
#include "bvh/bvh.h"
#include "scene/scene.h"

namespace obscura::bench {

// What bench-rays measures of one set of rays: its best and median GPU time over timed repeats,
// process CPU time, hit statistics, lavapipe's lane utilisation, and (verify > 0) the agreement of
// the first rays' hits with the CPU traversal (hit_agreement.h).
struct RaySetMeasurement {
  double bestMs = 0.0, medianMs = 0.0;
  double bestCpuMs = 0.0; // least process CPU time of one timed repeat
  double hitFraction = 0.0;
  double meanSteps = 0.0;
  // lavapipe runs 8 invocations in lock-step: a group's loop runs as long as its busiest lane's
  // (in trace.comp a lane's kTraceRaysPerLane rays together). Passes per ray as the groups run
  // them; meanSteps / it = lane utilisation.
  double meanGroupMaxSteps = 0.0;
  std::size_t mismatches = 0;           // traversal errors (bench/hit_agreement.h)
  std::size_t precisionDifferences = 0; // the other correct answer of a float-rounding-sensitive ray
  std::vector<std::string> mismatchExamples; // the first few traversal errors, for the report
};

struct RaySetOptions {
  int repeats = 3;          // timed repeats (the best and the median are kept)
  std::size_t verify = 0;   // the first `verify` rays checked against the CPU traversal
  bool backToBack = false;  // the repeats in one submission (a GPU)
};

RaySetMeasurement measureRaySet(render::RayTracer& tracer, const scene::Scene& scene, const bvh::Bvh& bvh,
                                const std::vector<gpu::GpuRay>& rays, render::TraceMode mode, const RaySetOptions& options);

} // namespace obscura::bench
