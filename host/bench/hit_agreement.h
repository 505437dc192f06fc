// hit_agreement.h — whether the GPU's answer for a ray is the CPU reference traversal's
// (bench-rays --verify), and when it is not, whether the two differ only as two correct float
// computations of the same test may.
//
// lavapipe runs the GLSL watertight test with the CPU's arithmetic, and the answers are identical.
// A real GPU may contract a*b+c into one fma and divides to 2.5 ulp (the Vulkan spec's
// precision), so a ray that grazes a triangle's edge, or meets two triangles at the same t (a
// shared edge, coplanar overlaps), or ends on a surface, can get the other correct answer.
// Whether two triangles are met at the same t is decided in double precision where the triangles
// are at hand: a float t of the watertight test is only as precise as the vertices' distance from
// the origin allows (Sponza: two overlapping 200-unit floor quads met 0.3 units away, exactly at
// the same t, came out 1.1e-5 apart relative, the nearer one swapping between CPU and GPU).
// Anything else is a traversal error.
#pragma once
#include "bvh/bvh.h"
#include "shared/host_device.h"

namespace obscura::bench {

enum class HitAgreement {
  Same,            // the same triangle (or both missed / both occluded)
  WithinPrecision, // different, at an edge (smallest barycentric <= kEdgeBarycentric), a tie in t or at an end of the ray
  Different,       // a traversal error
};

// The tolerances: far above a few ulp of float arithmetic, far below a triangle of a real scene.
inline constexpr float kEdgeBarycentric = 1e-4f;
inline constexpr float kRelativeT = 1e-5f;

// Where the ray meets a triangle's plane, in double precision: the answer that the float tests
// approximate. `inside`: the point lies in the triangle, up to kEdgeBarycentric.
struct ExactHit {
  double t = 0.0;
  bool inside = false;
};
ExactHit exactHit(const bvh::Ray& ray, const bvh::TriangleSoup& soup, std::uint32_t primitive);

// A closest-hit ray: the CPU's bvh::closestHit against the GPU's hit. Two hits on different
// triangles are a tie when their float t's are within kRelativeT, or, given the scene's
// triangles (`soup`, indexed by original triangle index), when the ray meets both inside at
// exact t's within kRelativeT.
HitAgreement closestHitAgreement(const bvh::Ray& ray, const bvh::Hit& cpu, const gpu::GpuHit& gpu,
                                 const bvh::TriangleSoup* soup = nullptr);

// A shadow ray: the CPU's bvh::anyHit (occluded or not) against the GPU's; `cpuClosest` is the
// CPU's closest hit on the same segment, whose barycentrics tell whether the CPU's occluder is
// grazed when the GPU saw none.
HitAgreement anyHitAgreement(const bvh::Ray& ray, bool cpuOccluded, const bvh::Hit& cpuClosest,
                             const gpu::GpuHit& gpu);

} // namespace obscura::bench
