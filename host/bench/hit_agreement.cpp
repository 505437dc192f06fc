#include "bench/hit_agreement.h"

#include <algorithm>
#include <cmath>

namespace obscura::render {
namespace {

bool atEdge(float u, float v) { return std::min({u, v, 1.0f - u - v}) <= kEdgeBarycentric; }

bool nearlyEqual(float a, float b) { return std::abs(a - b) <= kRelativeT * std::max({std::abs(a), std::abs(b), 1e-30f}); }

bool atRayEnd(const bvh::Ray& ray, float t) {
  return nearlyEqual(t, ray.tmin) || (std::isfinite(ray.tmax) && nearlyEqual(t, ray.tmax));
}

// A hit whose existence float rounding can decide: at a triangle's edge, or at an end of the ray.
bool fragileHit(const bvh::Ray& ray, float t, float u, float v) { return atEdge(u, v) || atRayEnd(ray, t); }

} // namespace

HitAgreement closestHitAgreement(const bvh::Ray& ray, const bvh::Hit& cpu, const gpu::GpuHit& gpu) {
  if (gpu.primitive == gpu::kTruncatedHit) return HitAgreement::Different;
  if (gpu.primitive == cpu.primitive) return HitAgreement::Same;
  const bool gpuHit = gpu.primitive != gpu::kInvalidIndex;
  if (gpuHit && cpu.hit()) {
    if (nearlyEqual(gpu.t, cpu.t)) return HitAgreement::WithinPrecision; // a tie
    // One side lost the nearer hit: only a fragile one may be lost.
    const bool gpuNearer = gpu.t < cpu.t;
    return (gpuNearer ? fragileHit(ray, gpu.t, gpu.u, gpu.v) : fragileHit(ray, cpu.t, cpu.u, cpu.v))
               ? HitAgreement::WithinPrecision
               : HitAgreement::Different;
  }
  const bool fragile = gpuHit ? fragileHit(ray, gpu.t, gpu.u, gpu.v) : fragileHit(ray, cpu.t, cpu.u, cpu.v);
  return fragile ? HitAgreement::WithinPrecision : HitAgreement::Different;
}

HitAgreement anyHitAgreement(const bvh::Ray& ray, bool cpuOccluded, const bvh::Hit& cpuClosest,
                             const gpu::GpuHit& gpu) {
  if (gpu.primitive == gpu::kTruncatedHit) return HitAgreement::Different;
  const bool gpuOccluded = gpu.primitive != gpu::kInvalidIndex;
  if (gpuOccluded == cpuOccluded) return HitAgreement::Same;
  const bool fragile = gpuOccluded ? fragileHit(ray, gpu.t, gpu.u, gpu.v)
                                   : cpuClosest.hit() && fragileHit(ray, cpuClosest.t, cpuClosest.u, cpuClosest.v);
  return fragile ? HitAgreement::WithinPrecision : HitAgreement::Different;
}

} // namespace obscura::render
