// binary_layout.h — the binary GPU layout of a built BVH (gpu::BvhBinaryNode, kBvhLayoutBinary),
// the one a GPU traverses (render/scene_data/bvh_layout.h chooses), and its CPU twin traversal.
//
// The layout is derived from the wide tree, not built anew: every wide node becomes a small
// binary tree over its (up to 8) children, found by agglomerative clustering (the pair whose
// union has the smallest surface area merged first: Walter et al., "Fast Agglomerative
// Clustering for Rendering", RT 2008, exhaustively over at most 8 boxes). Its leaves are the
// wide tree's leaf slots (1..3 triangles, which the SAH-optimal collapse chose), and its
// triangles are the wide tree's own, in the same order, so a hit's triangle texel is the same in
// both layouts and a refit of the wide tree followed by deriving again refits this one.
#pragma once
#include <cstdint>
#include <vector>

#include "bvh/bvh.h"

namespace obscura::bvh {

struct BinaryBvh {
  // nodes[0] is the root, a node's children follow it depth-first (left subtree first). Leaf
  // references hold the index of their first triangle in Bvh::triangles, not yet a texel: the
  // upload rebases them (binaryLeafTexel), as bvhTexels does the wide nodes' triangle bases.
  std::vector<gpu::BvhBinaryNode> nodes;
  std::uint32_t maxDepth = 0; // nodes on the longest path from the root to a leaf
};

BinaryBvh binaryLayout(const Bvh& bvh);

// References (shared/host_device.h): a node index, or a leaf of `count` triangles from `first`.
std::uint32_t binaryLeafRef(std::uint32_t first, std::uint32_t count);
bool isBinaryLeaf(std::uint32_t ref);
std::uint32_t binaryLeafFirst(std::uint32_t ref);
std::uint32_t binaryLeafCount(std::uint32_t ref);

// The same traversal shaders/lib/bvh.glsl runs on this layout (traverseBinary): nearer child
// first, the other pushed; boxes tested as intersectBox does (the GPU's cull on pop, which skips
// a child that a box test would skip anyway, is left out). Same answers as closestHit and
// anyHit over the wide nodes (ties in t to the lower primitive id).
Hit closestHitBinary(const Bvh& bvh, const BinaryBvh& binary, const Ray& ray);
bool anyHitBinary(const Bvh& bvh, const BinaryBvh& binary, const Ray& ray);

} // namespace obscura::bvh
