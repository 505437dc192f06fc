#include "bench/ray_set_measurement.h"

#include <algorithm>
#include <array>

#include <fmt/format.h>

#include "bench/cpu_time.h"
#include "bench/hit_agreement.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::bench {

RaySetMeasurement measureRaySet(render::RayTracer& tracer, const scene::Scene& scene, const bvh::Bvh& bvh,
                                const std::vector<gpu::GpuRay>& rays, render::TraceMode mode, const RaySetOptions& o) {
  RaySetMeasurement r;
  // Warm-up (pipeline JIT, caches) and hit statistics, then timed repeats.
  auto first = tracer.trace(rays, mode, true);
  std::size_t hits = 0;
  double steps = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (first.hits[i].primitive != gpu::kInvalidIndex) ++hits;
    steps += first.steps[i];
  }
  r.hitFraction = rays.empty() ? 0.0 : static_cast<double>(hits) / static_cast<double>(rays.size());
  r.meanSteps = rays.empty() ? 0.0 : steps / static_cast<double>(rays.size());
  // What lavapipe's 8-lane groups run: each lane traces its rays (the tracer's raysPerLane) in one
  // refilling loop (trace.comp), so a group runs as many passes as its busiest lane's rays take.
  constexpr std::size_t kLanes = 8;
  const std::size_t kBlock = kLanes * tracer.shape().raysPerLane;
  double groupPasses = 0.0;
  for (std::size_t b = 0; b < rays.size(); b += kBlock) {
    std::array<std::uint64_t, kLanes> lane{};
    for (std::size_t i = b; i < std::min(rays.size(), b + kBlock); ++i) lane[(i - b) % kLanes] += first.steps[i];
    groupPasses += static_cast<double>(*std::max_element(lane.begin(), lane.end()));
  }
  // Passes per ray as the groups run them: the mean per ray over the lane utilisation.
  r.meanGroupMaxSteps = rays.empty() ? 0.0 : kLanes * groupPasses / static_cast<double>(rays.size());
  std::vector<double> times, cpuMs;
  if (o.backToBack) { // a GPU: the repeats in one submission, so that its clocks stay up between them
    // Once untimed first (pipelines, caches). Not a cure: on an H200 the shadow set traced after
    // Sponza's 1M-ray CPU check ran at a fifth of its rate in every run, all five repeats alike;
    // warming up for 0.4 s of repeated traces made more sets do so (docs/BENCHMARKS.md,
    // "Traversal per device"), so a set's figure is checked against the other runs of its kernel.
    tracer.traceRepeated(rays, mode, static_cast<std::uint32_t>(o.repeats));
    double c0 = processCpuMs();
    times = tracer.traceRepeated(rays, mode, static_cast<std::uint32_t>(o.repeats)).repeatGpuMs;
    cpuMs.push_back((processCpuMs() - c0) / o.repeats);
  } else { // lavapipe: each repeat on its own, its process CPU time measured (the Embree ratio's)
    for (int k = 0; k < o.repeats; ++k) {
      double c0 = processCpuMs();
      times.push_back(tracer.trace(rays, mode).gpuMs);
      cpuMs.push_back(processCpuMs() - c0);
    }
  }
  r.bestCpuMs = *std::min_element(cpuMs.begin(), cpuMs.end());
  std::sort(times.begin(), times.end());
  r.bestMs = times.front();
  r.medianMs = times[times.size() / 2];
  // Optional check of the first `verify` rays against the CPU reference traversal.
  const bool shadowRays = mode == render::TraceMode::Any;
  const bvh::TriangleSoup soup = o.verify > 0 ? render::triangleSoup(scene) : bvh::TriangleSoup{};
  for (std::size_t i = 0; i < std::min(o.verify, rays.size()); ++i) {
    bvh::Ray ray{glm::vec3(rays[i].origin), glm::vec3(rays[i].direction), rays[i].origin.w, rays[i].direction.w};
    const bvh::Hit cpu = bvh::closestHit(bvh, ray);
    const bool cpuOccluded = shadowRays && bvh::anyHit(bvh, ray);
    const gpu::GpuHit& g = first.hits[i];
    const HitAgreement agreement =
        shadowRays ? anyHitAgreement(ray, cpuOccluded, cpu, g)
                   : closestHitAgreement(ray, cpu, g, &soup);
    if (agreement == HitAgreement::Different && ++r.mismatches <= 5) {
      r.mismatchExamples.push_back(fmt::format(
          "{} ray {}: origin ({}, {}, {}) direction ({}, {}, {}) t in ({}, {}); CPU closest t {} u {} v {} "
          "triangle {}{}; GPU t {} u {} v {} triangle {}",
          shadowRays ? "shadow" : "closest", i, ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x,
          ray.direction.y, ray.direction.z, ray.tmin, ray.tmax, cpu.t, cpu.u, cpu.v, cpu.primitive,
          shadowRays ? fmt::format(" (occluded: {})", cpuOccluded) : "", g.t, g.u, g.v, g.primitive));
    }
    if (agreement == HitAgreement::WithinPrecision) ++r.precisionDifferences;
  }
  return r;
}

} // namespace obscura::bench
