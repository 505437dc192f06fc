// wide_collapse.h — which binary nodes become the slots of each 8-wide node: the SAH-optimal
// collapse of Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on GPUs Through
// Compressed Wide BVHs", HPG 2017, §3.1 (a dynamic programme over the binary tree).
//
// Opening binary nodes greedily by surface area fills every wide node, but it cannot decide that
// a small subtree is cheaper as one leaf (its up to kLeafMaxTriangles triangles tested directly)
// than as a node, nor where a node's 8 slots are best spent among its subtrees. The programme
// finds, for every binary node n and every i <= 8, the cheapest way to cover n's subtree with at
// most i slots, bottom-up:
//
//   C(n, 1)   = min(C_leaf(n), C_node(n))
//   C(n, i)   = min(C(n, i - 1), min_{0<k<i} C(left, k) + C(right, i - k))      (i > 1)
//   C_node(n) = c_node A(n) + min_{0<k<8} C(left, k) + C(right, 8 - k)
//   C_leaf(n) = c_tri A(n) P(n)   when n's subtree holds P(n) <= kLeafMaxTriangles triangles
//
// (A: surface area; a binary leaf may only be a slot leaf). The host/bvh builder uses it to write
// the wide layout; the tree it gives is tested like any other (bvh_test.cpp).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace obscura::bvh {

// A node of the binary tree as the collapse sees it. Children have larger indices than their
// parent; index 0 is the root.
struct CollapseInput {
  float area = 0.0f;             // surface area of the node's box
  std::uint32_t triangles = 0;   // binary leaf: its triangle count; interior: 0
  std::uint32_t child[2] = {0, 0}; // interior only
  bool leaf() const { return triangles > 0; }
};

struct CollapseCosts {
  float node = 1.0f;     // c_node: visiting one wide node (per unit area)
  float triangle = 1.0f; // c_tri: testing one triangle (per unit area)
  std::uint32_t maxLeafTriangles = 3;
};

// One slot of a wide node: a binary node, either a slot leaf (its whole subtree's triangles,
// at most maxLeafTriangles) or the interior node of a wide child.
struct CollapsedSlot {
  std::uint32_t node;
  bool leaf;
};

class WideCollapse {
public:
  // Runs the programme over the nodes reachable from the interior root `nodes[0]`; `nodes` must
  // outlive the collapse.
  WideCollapse(std::span<const CollapseInput> nodes, const CollapseCosts& costs);

  // The slots (1..8) of the wide node made from interior binary node `n` (the root, or a node
  // that an earlier call returned with leaf == false).
  std::vector<CollapsedSlot> slots(std::uint32_t n) const;

  // C_node(root) divided by the root's area: the wide tree's SAH cost.
  double cost() const;

private:
  static constexpr int kWidth = 8;
  void solve(std::uint32_t n);
  void collect(std::uint32_t n, int i, std::vector<CollapsedSlot>& out) const;

  std::span<const CollapseInput> nodes_;
  CollapseCosts costs_;
  std::vector<std::uint32_t> subtreeTriangles_;   // P(n)
  std::vector<float> cost_;                       // C(n, i) at n * kWidth + i - 1
  // How C(n, i) was reached: for i > 1, 0 = as C(n, i - 1), k = left gets k slots, right i - k;
  // for i = 1, 0 = as a leaf, 1 = as a node.
  std::vector<std::uint8_t> choice_;
  std::vector<std::uint8_t> nodeSplit_;           // C_node(n)'s k
};

} // namespace obscura::bvh
