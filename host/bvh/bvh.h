// bvh.h — bounding volume hierarchy over a triangle soup: build, GPU layout, CPU traversal.
//
// The builder is binned SAH (Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", 2007), parallel over subtrees, collapsed SAH-optimally (wide_collapse.h) into
// 8-wide nodes with 8-bit quantised child boxes (Ylitie, Karras & Laine 2017), see
// shaders/shared/host_device.h and wide_node.h. The CPU traversal walks the same wide nodes and
// is the reference the GPU is tested against.
#pragma once
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "shared/host_device.h"

namespace obscura::bvh {

struct BuildOptions {
  int bins = 32;                 // SAH bins per axis
  float traversalCost = 1.0f;    // SAH cost of visiting one node, relative to...
  float intersectionCost = 1.0f; // ...the cost of testing one triangle
  float wideNodeCost = 1.0f;     // the collapse's cost of visiting one 8-wide node (wide_collapse.h)
  std::uint32_t maxLeafSize = 3; // triangles of a wide leaf slot, <= gpu::kLeafMaxTriangles
  // Triangles of a binary leaf while the SAH could still split it: 1, as Ylitie et al. build, so
  // that the collapse, not the binary build, decides which triangles share a leaf slot (Sponza:
  // 13.1 -> 12.8 loop passes per closest-hit ray, docs/BENCHMARKS.md). <= maxLeafSize.
  std::uint32_t binaryLeafSize = 1;
  unsigned threads = 0;          // 0 = hardware concurrency
  // Spatial splits (SBVH, Stich et al. 2009): extra references the build may add by clipping
  // triangles at split planes, as a share of the triangle count; 0 = none (every triangle stored
  // once). A triangle split this way is stored once in every leaf that holds a piece of it.
  // Measured on lavapipe (docs/BENCHMARKS.md): fewer loop passes per ray, but faster closest-hit
  // rays on Sponza only where lavapipe's threads flush subnormals, and slower shadow rays, so the
  // renderer builds without them; `bench-rays --spatial-splits` measures a scene with them.
  float spatialSplitBudget = 0.0f;
  // A spatial split is tried at a node whose object split's children overlap by more than this
  // share of the root's surface area (the paper's alpha).
  float spatialSplitOverlap = 1e-5f;
};

struct BuildStats {
  double buildSeconds = 0.0;
  std::uint32_t nodeCount = 0;   // wide nodes in the GPU layout
  std::uint32_t leafCount = 0;   // leaf children (of 1..maxLeafSize triangles)
  std::uint32_t maxDepth = 0;    // of the wide tree (root's children: 1); <= gpu::kBvhMaxDepth, always
  double sahCost = 0.0;          // SAH cost of the binary tree before collapsing (root area = 1)
  double wideSahCost = 0.0;      // SAH cost of the 8-wide tree, as the collapse minimised it
  std::uint32_t medianFallbacks = 0; // nodes split by median to honour the depth bound
  std::uint32_t spatialSplits = 0;   // nodes split by a plane that clips triangles
  std::uint32_t references = 0;      // triangles stored in the leaves (> triangles with spatial splits)
};

// Input: one entry per triangle, its three world-space vertices.
struct TriangleSoup {
  std::vector<glm::vec3> v0, v1, v2;
  std::size_t size() const { return v0.size(); }
};

struct Bvh {
  // GPU layout, ready to upload: nodes[0] is the root, a wide node even for a scene of one leaf
  // (one used slot) or none (no used slot). A node's interior children are consecutive and
  // follow it (breadth-first order). An empty soup leaves `triangles` empty: pad the GPU
  // buffer, Vulkan buffers cannot have size 0.
  std::vector<gpu::BvhNode> nodes;
  std::vector<gpu::BvhTriangle> triangles; // in the order leaves need them; .v0.w = original index as float bits
  std::vector<std::uint32_t> order;        // order[i] = original index of triangles[i]
  BuildStats stats;
};

// Builds a BVH. Degenerate triangles are allowed (they simply never report a hit). An empty soup
// gives a root with two empty children.
Bvh build(const TriangleSoup& soup, const BuildOptions& options = {});

// The uvec4 registers of compact stack (shared/host_device.h) that no traversal of `bvh` can
// overflow: ceil((depth - 2) / 4), at least 1; 0 where `bvh` is beyond the compact stack's limits
// (more than kBvhCompactStackNodes nodes, or deeper than kBvhCompactStackMaxDepth).
std::uint32_t compactStackVectors(const Bvh& bvh);
// Whether a kernel specialised with `kernelVectors` (kSpecConstantCompactStack; 0: the general
// kernel) may trace a BVH that needs `needed` (compactStackVectors).
inline bool compactStackHolds(std::uint32_t kernelVectors, std::uint32_t needed) {
  return kernelVectors == 0 || (needed != 0 && kernelVectors >= needed);
}

// Refits `bvh` to the moved vertices of the same triangles (`soup` indexed as when it was built):
// the tree keeps its topology, every box is recomputed bottom-up and quantised again. Linear in the size, so an object
// edit updates the structure without a rebuild; the tree's quality degrades with large moves
// (measured in docs/BENCHMARKS.md), and a rebuild restores it.
void refit(Bvh& bvh, const TriangleSoup& soup);

// ---- CPU traversal (the reference).
struct Ray {
  glm::vec3 origin;
  glm::vec3 direction; // need not be unit; t is measured in units of |direction|
  float tmin = 0.0f;
  float tmax = std::numeric_limits<float>::infinity();
};

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;            // barycentrics of v1 and v2
  std::uint32_t primitive = gpu::kInvalidIndex; // original triangle index
  bool hit() const { return primitive != gpu::kInvalidIndex; }
};

// Closest hit in (tmin, tmax]; ties in t go to the lower original primitive index.
Hit closestHit(const Bvh& bvh, const Ray& ray);
// True when anything is hit in (tmin, tmax); `hitT`, if given, gets the distance of the hit found
// (not necessarily the closest): the ray is blocked within that much of its origin.
bool anyHit(const Bvh& bvh, const Ray& ray, float* hitT = nullptr);
// Brute force over every triangle, same rules: the oracle for closestHit and for the GPU.
Hit closestHitBruteForce(const TriangleSoup& soup, const Ray& ray);

} // namespace obscura::bvh
