// cpu_traverse.cpp — reference traversal of the GPU-layout BVH, and the brute-force oracle.
//
// Stack traversal of a BVH2 whose nodes hold both children's boxes (Aila & Laine, "Understanding
// the Efficiency of Ray Traversal on GPUs", 2009): test both boxes, continue with the nearer hit
// child, push the farther. Each interior node on the path pushes at most one entry, so a stack of
// kBvhStackSize >= kBvhMaxDepth entries cannot overflow.
#include <bit>
#include <cmath>
#include <limits>

#include "bvh/bvh.h"
#include "bvh/triangle_intersect.h"

namespace obscura::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Pharr, Jakob & Humphreys, "Physically Based Rendering" 3rd ed. §3.9.1: gamma(n) bounds the
// relative error of n chained float operations.
constexpr float gamma(int n) {
  constexpr float e = std::numeric_limits<float>::epsilon() * 0.5f;
  return static_cast<float>(n) * e / (1.0f - static_cast<float>(n) * e);
}
// Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013: scaling the far distance by 1 + 2 gamma(3)
// makes the slab test conservative, so a box is never missed by a ray that hits a triangle in it.
// We scale the current best t by the same factor, so that a triangle lying on its box's face
// whose t equals the best t (a tie, won by the lower primitive id) is not culled by rounding.
constexpr float kFarScale = 1.0f + 2.0f * gamma(3);

struct BoxRay {
  glm::vec3 origin;
  glm::vec3 invDir;  // 1/d, +-inf for zero components
  int nearIsHi[3];   // per axis: is the near plane the box's hi side?
};

BoxRay makeBoxRay(const Ray& ray) {
  BoxRay r;
  r.origin = ray.origin;
  for (int a = 0; a < 3; ++a) {
    r.invDir[a] = 1.0f / ray.direction[a];
    // The sign bit, not a comparison, so that -0 (inverse -inf) picks hi as the near plane.
    r.nearIsHi[a] = std::signbit(r.invDir[a]) ? 1 : 0;
  }
  return r;
}

// Slab test with near/far planes picked by the direction's sign (Williams, Barrus, Morley &
// Shirley, "An Efficient and Robust Ray-Box Intersection Algorithm", 2005). Picking by sign, not
// by min/max of the two plane distances, is what makes the inverted box (lo = +inf, hi = -inf) of
// an empty child miss every ray. A zero direction component with the origin exactly on a slab
// plane gives 0 * inf = NaN; the comparisons below ignore a NaN, i.e. treat that axis as not
// constraining (the origin is on the box's boundary in it). Returns the entry distance or +inf.
float boxEntry(const BoxRay& r, const glm::vec4& lo, const glm::vec4& hi, float tmin, float tmax) {
  float tNear = tmin;
  float tFar = tmax;
  for (int a = 0; a < 3; ++a) {
    const float nearPlane = r.nearIsHi[a] ? hi[a] : lo[a];
    const float farPlane = r.nearIsHi[a] ? lo[a] : hi[a];
    const float t0 = (nearPlane - r.origin[a]) * r.invDir[a];
    const float t1 = (farPlane - r.origin[a]) * r.invDir[a] * kFarScale;
    tNear = t0 > tNear ? t0 : tNear;
    tFar = t1 < tFar ? t1 : tFar;
  }
  return tNear <= tFar ? tNear : kInf;
}

struct StackEntry {
  std::uint32_t ref;
  float tEntry;
};

bool isLeaf(std::uint32_t ref) { return (ref & gpu::kLeafFlag) != 0; }

// Shared traversal loop: visit(first, count) tests a leaf's triangles and returns true to stop;
// tCull() is the current far limit for boxes (already scaled).
template <class Visit, class Cull>
void traverse(const Bvh& bvh, const Ray& ray, Visit&& visit, Cull&& tCull) {
  if (bvh.nodes.empty()) return;
  const BoxRay boxRay = makeBoxRay(ray);
  StackEntry stack[gpu::kBvhStackSize];
  unsigned sp = 0;
  std::uint32_t ref = 0; // the root, an interior node
  for (;;) {
    if (isLeaf(ref)) {
      const std::uint32_t first = ref & gpu::kLeafFirstMask;
      const std::uint32_t count = ((ref >> gpu::kLeafCountShift) & gpu::kLeafCountMask) + 1;
      if (visit(first, count)) return;
    } else {
      const gpu::BvhNode& node = bvh.nodes[ref];
      const float limit = tCull();
      const float t0 = boxEntry(boxRay, node.lo0, node.hi0, ray.tmin, limit);
      const float t1 = boxEntry(boxRay, node.lo1, node.hi1, ray.tmin, limit);
      const std::uint32_t ref0 = std::bit_cast<std::uint32_t>(node.lo0.w);
      const std::uint32_t ref1 = std::bit_cast<std::uint32_t>(node.hi0.w);
      // The empty child of a one-leaf root has an inverted box, which boxEntry() already
      // rejects, and the ref kInvalidIndex, checked too, as the GPU traversal does.
      const bool hit0 = t0 != kInf && ref0 != gpu::kInvalidIndex;
      const bool hit1 = t1 != kInf && ref1 != gpu::kInvalidIndex;
      if (hit0 && hit1) {
        // Nearer first; the farther waits on the stack with its entry distance.
        const bool firstIs0 = t0 <= t1;
        stack[sp++] = firstIs0 ? StackEntry{ref1, t1} : StackEntry{ref0, t0};
        ref = firstIs0 ? ref0 : ref1;
        continue;
      }
      if (hit0 || hit1) {
        ref = hit0 ? ref0 : ref1;
        continue;
      }
    }
    // Pop, skipping entries that a hit found since they were pushed has made too far.
    for (;;) {
      if (sp == 0) return;
      const StackEntry e = stack[--sp];
      if (e.tEntry <= tCull()) {
        ref = e.ref;
        break;
      }
    }
  }
}

// The closest-hit rule shared by the BVH and brute force: smaller t, ties to the lower id.
bool closer(float t, std::uint32_t primitive, const Hit& best) {
  return t < best.t || (t == best.t && primitive < best.primitive);
}

} // namespace

Hit closestHit(const Bvh& bvh, const Ray& ray) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  Hit best;
  float tmax = ray.tmax; // closed bound passed to the triangle test: best t once there is a hit
  traverse(
      bvh, ray,
      [&](std::uint32_t first, std::uint32_t count) {
        for (std::uint32_t i = first; i < first + count; ++i) {
          const gpu::BvhTriangle& tri = bvh.triangles[i];
          float t, u, v;
          if (!intersectTriangle(wr, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2),
                                 ray.tmin, tmax, t, u, v))
            continue;
          const std::uint32_t primitive = std::bit_cast<std::uint32_t>(tri.v0.w);
          if (closer(t, primitive, best)) {
            best = Hit{t, u, v, primitive};
            tmax = t;
          }
        }
        return false;
      },
      [&] { return tmax * kFarScale; });
  return best;
}

bool anyHit(const Bvh& bvh, const Ray& ray) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  bool found = false;
  traverse(
      bvh, ray,
      [&](std::uint32_t first, std::uint32_t count) {
        for (std::uint32_t i = first; i < first + count; ++i) {
          const gpu::BvhTriangle& tri = bvh.triangles[i];
          float t, u, v;
          // The triangle test is closed at tmax; anyHit's interval is open there.
          if (intersectTriangle(wr, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2),
                                ray.tmin, ray.tmax, t, u, v) &&
              t < ray.tmax) {
            found = true;
            return true;
          }
        }
        return false;
      },
      [&] { return ray.tmax * kFarScale; });
  return found;
}

Hit closestHitBruteForce(const TriangleSoup& soup, const Ray& ray) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  Hit best;
  float tmax = ray.tmax;
  for (std::size_t i = 0; i < soup.size(); ++i) {
    float t, u, v;
    if (!intersectTriangle(wr, soup.v0[i], soup.v1[i], soup.v2[i], ray.tmin, tmax, t, u, v))
      continue;
    const std::uint32_t primitive = static_cast<std::uint32_t>(i);
    if (closer(t, primitive, best)) {
      best = Hit{t, u, v, primitive};
      tmax = t;
    }
  }
  return best;
}

} // namespace obscura::bvh
