// cpu_traverse.cpp — reference traversal of the wide BVH, and the brute-force oracle.
//
// The child boxes are tested exactly as shaders/lib/bvh.glsl tests them (wide_node.h:
// hitChildren), and interior children are visited in the same octant order; the GPU's pass
// structure (one node and one triangle per loop pass) is its own business. Each node visited
// pushes at most one entry (a node group: first child, pending slots), so a stack of
// kBvhStackSize >= kBvhMaxDepth entries cannot overflow.
#include <bit>
#include <cmath>
#include <limits>

#include "bvh/bvh.h"
#include "bvh/triangle_intersect.h"
#include "bvh/wide_node.h"

namespace obscura::bvh {
namespace {

// Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013: the far distance of a box is scaled by
// 1 + 2 gamma(7) inside hitChildren() (kBoxFarScale), which makes the float slab test
// conservative; we pass the current best t itself, so a triangle lying on its box's face whose t
// equals the best t (a tie, won by the lower primitive id) is not culled by rounding.

// A node group: interior children of node `node` not visited yet, as a bit mask over visit
// order (bit k = slot k ^ octant), as the GPU keeps it.
struct Group {
  std::uint32_t node;
  std::uint32_t pending;
};

// Shared traversal loop: visit(first, mask) tests the triangles first + i for the bits i of
// `mask` and returns true to stop; tCull() is the current far limit for boxes.
template <class Visit, class Cull>
void traverse(const Bvh& bvh, const Ray& ray, Visit&& visit, Cull&& tCull) {
  if (bvh.nodes.empty()) return;
  const BoxRay boxRay = makeBoxRay(ray.origin, ray.direction);
  Group stack[gpu::kBvhStackSize];
  unsigned sp = 0;
  std::uint32_t current = 0; // the root
  for (;;) {
    const gpu::BvhNode& node = bvh.nodes[current];
    const std::uint32_t hits = hitChildren(node, boxRay, ray.tmin, tCull());
    std::uint32_t triangleBits = 0, pending = 0;
    const std::uint32_t imask = internalMask(node);
    for (unsigned s = 0; s < gpu::kBvhWidth; ++s) {
      if (!(hits >> s & 1u)) continue;
      const std::uint32_t meta = slotMeta(node, s);
      if (imask >> s & 1u) pending |= 1u << (s ^ boxRay.octant);
      else triangleBits |= ((1u << (meta & 3u)) - 1u) << (meta >> 2 & 31u);
    }
    if (triangleBits != 0 && visit(firstTriangle(node), triangleBits)) return;
    if (pending != 0) {
      // Descend into the first pending child in visit order; the rest wait on the stack.
      const unsigned key = static_cast<unsigned>(std::countr_zero(pending));
      pending &= pending - 1;
      const std::uint32_t child = childNodeIndex(node, key ^ boxRay.octant);
      if (pending != 0) stack[sp++] = {current, pending};
      current = child;
      continue;
    }
    if (sp == 0) return;
    Group& top = stack[sp - 1];
    const gpu::BvhNode& parent = bvh.nodes[top.node];
    const unsigned key = static_cast<unsigned>(std::countr_zero(top.pending));
    top.pending &= top.pending - 1;
    current = childNodeIndex(parent, key ^ boxRay.octant);
    if (top.pending == 0) --sp;
  }
}

} // namespace

Hit closestHit(const Bvh& bvh, const Ray& ray) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  Hit best;
  float tmax = ray.tmax; // closed bound passed to the triangle test: best t once there is a hit
  traverse(
      bvh, ray,
      [&](std::uint32_t first, std::uint32_t mask) {
        for (; mask != 0; mask &= mask - 1) {
          const gpu::BvhTriangle& tri = bvh.triangles[first + static_cast<std::uint32_t>(std::countr_zero(mask))];
          float t, u, v;
          if (!intersectTriangle(wr, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2),
                                 ray.tmin, tmax, t, u, v))
            continue;
          const std::uint32_t primitive = std::bit_cast<std::uint32_t>(tri.v0.w);
          if (t < best.t || (t == best.t && primitive < best.primitive)) {
            best = Hit{t, u, v, primitive};
            tmax = t;
          }
        }
        return false;
      },
      [&] { return tmax; });
  return best;
}

bool anyHit(const Bvh& bvh, const Ray& ray, float* hitT) {
  const WatertightRay wr = prepareWatertightRay(ray.origin, ray.direction);
  bool found = false;
  traverse(
      bvh, ray,
      [&](std::uint32_t first, std::uint32_t mask) {
        for (; mask != 0; mask &= mask - 1) {
          const gpu::BvhTriangle& tri = bvh.triangles[first + static_cast<std::uint32_t>(std::countr_zero(mask))];
          float t, u, v;
          // The triangle test is closed at tmax; anyHit's interval is open there.
          if (intersectTriangle(wr, glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2),
                                ray.tmin, ray.tmax, t, u, v) &&
              t < ray.tmax) {
            found = true;
            if (hitT) *hitT = t;
            return true;
          }
        }
        return false;
      },
      [&] { return ray.tmax; });
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
    if (t < best.t || (t == best.t && primitive < best.primitive)) {
      best = Hit{t, u, v, primitive};
      tmax = t;
    }
  }
  return best;
}

} // namespace obscura::bvh
