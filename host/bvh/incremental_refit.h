// incremental_refit.h — refit (bvh.h) of the nodes above a few moved triangles only.
//
// A whole refit visits every node: 2.3 ms of every object move on modern-hall (BENCHMARKS), the
// largest part of a move's host work once the reach replays. An object's triangles lie under a
// few leaves; only those leaves' nodes and their ancestors change. Kept per tree: each node's
// parent, the node whose leaf holds each triangle, where each original triangle lies (several
// leaves with spatial splits), and each node's exact box (what refit() computes bottom-up). A
// node is refitted as refit() refits it, from its children's exact boxes, so after it the tree
// equals refit()'s wherever the nodes left alone were written by a refit or by the builder from
// the same boxes (a tree without spatial splits: BvhRefit.IncrementalRefitEqualsAWholeRefit);
// with spatial splits the builder's leaf boxes are clipped, and refitted nodes use the whole
// triangles' boxes (conservative, as refit()).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/wide_node.h"

namespace obscura::bvh {

class IncrementalRefit {
public:
  // Linear in the tree, once per tree (after its build).
  explicit IncrementalRefit(const Bvh& bvh);

  // Triangles `ids` (original indices, as in the soup the tree was built from) now have the
  // vertices `moved` (moved.v0[k] is triangle ids[k]'s): their copies in the tree are replaced and
  // the nodes above them refitted. Returns the nodes refitted (highest index first).
  std::span<const std::uint32_t> refit(Bvh& bvh, std::span<const std::uint32_t> ids, const TriangleSoup& moved);

private:
  std::vector<std::uint32_t> parent_;     // per node (the root's: itself)
  std::vector<std::uint32_t> leafNode_;   // per position in Bvh::triangles: the node whose leaf holds it
  std::vector<std::uint32_t> placesFrom_; // per original triangle: its positions are places_[placesFrom_[id] ..
  std::vector<std::uint32_t> places_;     // .. placesFrom_[id + 1])
  std::vector<Box> nodeBox_;              // per node: exact bounds of what lies below
  std::vector<std::uint8_t> marked_;      // per node, during refit()
  std::vector<std::uint32_t> refitted_;
};

} // namespace obscura::bvh
