// insert.h — a few triangles added to a built wide BVH without rebuilding it (an emissive quad
// added by an edit: rebuilding modern-hall's tree for its two triangles was ~20 ms of host work).
//
// The triangles go into one new leaf slot of an existing node: of the nodes with a free slot and
// room for the leaf's triangle offset, the one whose box grows least (in surface area) to hold them. That node's leaf triangles are copied to the end of
// Bvh::triangles with the new ones after them (a node's leaves address its triangles from one
// base, and the new ones are appended); the old copies stay, unreferenced. No node is added, so the
// tree's depth, and with it the traversal stack the kernels are specialised for, stays. The
// node's and its ancestors' boxes are then refitted exactly (IncrementalRefit, made for the tree
// as it now is). The tree's quality is that of the one before with a leaf hung where the new
// triangles are; edits that add many triangles (an inserted object) rebuild instead.
#pragma once
#include <cstdint>
#include <span>

#include "bvh/bvh.h"

namespace obscura::bvh {

// Adds triangles `ids` (original indices past every one in the tree, as the soup now numbers
// them) with vertices `added` (added.v0[k] is ids[k]'s), at most gpu::kLeafMaxTriangles, as one
// leaf. False, and the tree unchanged, when no node on the way has room: rebuild then. The boxes
// above the new leaf are left conservative but not exact: refit them (IncrementalRefit::refit
// over `ids`) before tracing.
bool insertTriangles(Bvh& bvh, std::span<const std::uint32_t> ids, const TriangleSoup& added);

} // namespace obscura::bvh
