#include "bench/hit_agreement.h"

#include <algorithm>
#include <cmath>

namespace obscura::bench {
namespace {

bool atEdge(float u, float v) { return std::min({u, v, 1.0f - u - v}) <= kEdgeBarycentric; }

template <typename Real> bool nearlyEqual(Real a, Real b) {
  return std::abs(a - b) <= Real(kRelativeT) * std::max({std::abs(a), std::abs(b), Real(1e-30f)});
}

bool atRayEnd(const bvh::Ray& ray, float t) {
  return nearlyEqual(t, ray.tmin) || (std::isfinite(ray.tmax) && nearlyEqual(t, ray.tmax));
}

// A hit whose existence float rounding can decide: at a triangle's edge, or at an end of the ray.
bool fragileHit(const bvh::Ray& ray, float t, float u, float v) { return atEdge(u, v) || atRayEnd(ray, t); }

} // namespace

HitAgreement closestHitAgreement(const bvh::Ray& ray, const bvh::Hit& cpu, const gpu::GpuHit& gpu,
                                 const bvh::TriangleSoup* soup) {
  if (gpu.primitive == gpu::kTruncatedHit) return HitAgreement::Different;
  if (gpu.primitive == cpu.primitive) return HitAgreement::Same;
  const bool gpuHit = gpu.primitive != gpu::kInvalidIndex;
  if (gpuHit && cpu.hit()) {
    if (nearlyEqual(gpu.t, cpu.t)) return HitAgreement::WithinPrecision; // a tie
    if (soup) { // a tie of the exact t's that the float t's missed
      const ExactHit a = exactHit(ray, *soup, cpu.primitive), b = exactHit(ray, *soup, gpu.primitive);
      if (a.inside && b.inside && nearlyEqual(a.t, b.t)) return HitAgreement::WithinPrecision;
    }
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

ExactHit exactHit(const bvh::Ray& ray, const bvh::TriangleSoup& soup, std::uint32_t primitive) {
  if (primitive >= soup.size()) return {};
  const glm::dvec3 o = ray.origin, d = ray.direction;
  const glm::dvec3 v0 = soup.v0[primitive], e1 = glm::dvec3(soup.v1[primitive]) - v0,
                   e2 = glm::dvec3(soup.v2[primitive]) - v0;
  // Möller & Trumbore's solve of o + t d = v0 + u e1 + v e2 (Cramer's rule), in double.
  const glm::dvec3 p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (det == 0.0) return {};
  const glm::dvec3 s = o - v0, q = glm::cross(s, e1);
  const double u = glm::dot(s, p) / det, v = glm::dot(d, q) / det;
  return {glm::dot(e2, q) / det, std::min({u, v, 1.0 - u - v}) >= -double(kEdgeBarycentric)};
}

} // namespace obscura::bench
