// wide_collapse_test.cpp — the collapse's programme against exhaustive search on small trees,
// and the tree it emits against the cost it reports.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/wide_collapse.h"

namespace obscura::bvh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A random binary tree of `leaves` leaves in pre-order (children after their parent), with
// areas that shrink downwards (a child's area is a random fraction of its parent's) and
// 1..maxLeafTriangles triangles a leaf (the builder's binary leaves never hold more).
std::vector<CollapseInput> randomTree(int leaves, std::uint32_t maxLeafTriangles, std::mt19937& rng) {
  std::uniform_real_distribution<float> frac(0.2f, 0.95f);
  std::uniform_int_distribution<int> tris(1, static_cast<int>(maxLeafTriangles));
  std::vector<CollapseInput> nodes;
  std::function<std::uint32_t(int, float)> make = [&](int n, float area) {
    const auto index = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back({});
    nodes[index].area = area;
    if (n == 1) {
      nodes[index].triangles = static_cast<std::uint32_t>(tris(rng));
      return index;
    }
    const int left = std::uniform_int_distribution<int>(1, n - 1)(rng);
    const std::uint32_t l = make(left, area * frac(rng));
    const std::uint32_t r = make(n - left, area * frac(rng));
    nodes[index].child[0] = l;
    nodes[index].child[1] = r;
    return index;
  };
  make(leaves, 1.0f);
  return nodes;
}

std::uint32_t triangles(const std::vector<CollapseInput>& t, std::uint32_t n) {
  return t[n].leaf() ? t[n].triangles : triangles(t, t[n].child[0]) + triangles(t, t[n].child[1]);
}

// Every way to cover the subtree of n by a set of its nodes (a cut), of at most `limit` nodes.
std::vector<std::vector<std::uint32_t>> cuts(const std::vector<CollapseInput>& t, std::uint32_t n,
                                             std::size_t limit) {
  std::vector<std::vector<std::uint32_t>> out = {{n}};
  if (t[n].leaf()) return out;
  for (const auto& a : cuts(t, t[n].child[0], limit))
    for (const auto& b : cuts(t, t[n].child[1], limit)) {
      if (a.size() + b.size() > limit) continue;
      std::vector<std::uint32_t> c = a;
      c.insert(c.end(), b.begin(), b.end());
      out.push_back(c);
    }
  return out;
}

// The cheapest wide tree by trying every cut of every wide node: the slot cost of n (a leaf of
// its whole subtree, or a wide node whose slots are the best cut below it).
double exhaustiveSlotCost(const std::vector<CollapseInput>& t, std::uint32_t n, const CollapseCosts& c);

double exhaustiveNodeCost(const std::vector<CollapseInput>& t, std::uint32_t n, const CollapseCosts& c) {
  double best = kInf;
  for (const auto& a : cuts(t, t[n].child[0], 7))
    for (const auto& b : cuts(t, t[n].child[1], 8 - a.size())) {
      double sum = 0.0;
      for (const std::uint32_t s : a) sum += exhaustiveSlotCost(t, s, c);
      for (const std::uint32_t s : b) sum += exhaustiveSlotCost(t, s, c);
      best = std::min(best, sum);
    }
  return double{c.node} * t[n].area + best;
}

double exhaustiveSlotCost(const std::vector<CollapseInput>& t, std::uint32_t n, const CollapseCosts& c) {
  const std::uint32_t p = triangles(t, n);
  const double leaf = p <= c.maxLeafTriangles ? double{c.triangle} * t[n].area * p : kInf;
  return t[n].leaf() ? leaf : std::min(leaf, exhaustiveNodeCost(t, n, c));
}

// The cost of the tree that slots() emits, and checks on its shape: every triangle in exactly
// one leaf slot, leaves within the size limit, 1..8 slots a node.
double emittedCost(const WideCollapse& collapse, const std::vector<CollapseInput>& t, std::uint32_t n,
                   const CollapseCosts& c, std::uint32_t& trianglesSeen) {
  const std::vector<CollapsedSlot> slots = collapse.slots(n);
  EXPECT_GE(slots.size(), 1u);
  EXPECT_LE(slots.size(), 8u);
  double sum = double{c.node} * t[n].area;
  for (const CollapsedSlot& s : slots) {
    if (s.leaf) {
      const std::uint32_t p = triangles(t, s.node);
      EXPECT_LE(p, c.maxLeafTriangles);
      trianglesSeen += p;
      sum += double{c.triangle} * t[s.node].area * p;
    } else {
      EXPECT_FALSE(t[s.node].leaf());
      sum += emittedCost(collapse, t, s.node, c, trianglesSeen);
    }
  }
  return sum;
}

TEST(WideCollapse, MatchesExhaustiveSearchAndEmitsTheTreeItCosts) {
  std::mt19937 rng(7);
  const CollapseCosts costSets[] = {{1.0f, 1.0f, 3}, {1.0f, 0.3f, 3}, {2.0f, 1.0f, 3}, {1.0f, 1.0f, 1}};
  int trees = 0;
  for (const CollapseCosts& c : costSets)
    for (int leaves = 2; leaves <= 11; ++leaves)
      for (int k = 0; k < 4; ++k) {
        const std::vector<CollapseInput> t = randomTree(leaves, c.maxLeafTriangles, rng);
        const WideCollapse collapse(t, c);
        const double expected = exhaustiveNodeCost(t, 0, c);
        EXPECT_NEAR(collapse.cost(), expected, 1e-5 * expected) << leaves << " leaves";
        std::uint32_t seen = 0;
        EXPECT_NEAR(emittedCost(collapse, t, 0, c, seen), expected, 1e-5 * expected) << leaves << " leaves";
        EXPECT_EQ(seen, triangles(t, 0));
        ++trees;
      }
  EXPECT_EQ(trees, 160);
}

// A subtree of two one-triangle leaves takes two slots where that is cheaper than one leaf of
// both, and one leaf slot where the two cost the same (one slot fewer).
TEST(WideCollapse, SplitsASubtreeIntoSlotsOnlyWhereThatIsCheaper) {
  std::vector<CollapseInput> t(5);
  t[0] = {1.0f, 0, {1, 2}};
  t[1] = {0.9f, 0, {3, 4}};
  t[2] = {0.1f, 2, {}};
  t[3] = {0.5f, 1, {}};
  t[4] = {0.5f, 1, {}};
  const CollapseCosts c{1.0f, 1.0f, 3};
  const WideCollapse collapse(t, c);
  // Node 1 as one leaf of 2: 0.9 * 2 = 1.8; as the two slots of its leaves: 0.5 + 0.5 = 1.0.
  const std::vector<CollapsedSlot> slots = collapse.slots(0);
  ASSERT_EQ(slots.size(), 3u);
  EXPECT_TRUE(slots[0].leaf && slots[1].leaf && slots[2].leaf);
  EXPECT_EQ(slots[0].node, 3u);
  EXPECT_EQ(slots[1].node, 4u);
  EXPECT_EQ(slots[2].node, 2u);
  EXPECT_NEAR(collapse.cost(), 1.0 + 1.0 + 0.2, 1e-6);
  // Halves as large as node 1: two slots cost 1.8, the same as one leaf of both.
  t[3].area = t[4].area = 0.9f;
  const WideCollapse tie(t, c);
  const std::vector<CollapsedSlot> tieSlots = tie.slots(0);
  ASSERT_EQ(tieSlots.size(), 2u);
  EXPECT_TRUE(tieSlots[0].leaf);
  EXPECT_EQ(tieSlots[0].node, 1u);
}

TEST(WideCollapse, RejectsALeafRootAndChildrenBeforeTheirParent) {
  std::vector<CollapseInput> leafRoot(1);
  leafRoot[0].triangles = 1;
  EXPECT_THROW(WideCollapse(leafRoot, CollapseCosts{}), std::invalid_argument);
  std::vector<CollapseInput> backwards(3);
  backwards[0] = {1.0f, 0, {1, 0}};
  backwards[1] = {0.5f, 1, {}};
  EXPECT_THROW(WideCollapse(backwards, CollapseCosts{}), std::invalid_argument);
}

} // namespace
} // namespace obscura::bvh
