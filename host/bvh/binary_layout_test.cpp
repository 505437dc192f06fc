// binary_layout_test.cpp — the binary layout derived from the wide tree: every triangle in one
// leaf, boxes that contain what lies below them, the depth it reports, and its CPU traversal
// giving exactly the wide traversal's answers.
#include "bvh/binary_layout.h"

#include <bit>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace obscura::bvh {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

TriangleSoup randomSoup(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), sym(-1.0f, 1.0f);
  TriangleSoup soup;
  for (std::size_t i = 0; i < count; ++i) {
    const glm::vec3 c(10.0f * unit(rng), 10.0f * unit(rng), 10.0f * unit(rng));
    const float size = std::pow(10.0f, -3.0f * unit(rng) + 0.3f);
    soup.v0.push_back(c + size * glm::vec3(sym(rng), sym(rng), sym(rng)));
    soup.v1.push_back(c + size * glm::vec3(sym(rng), sym(rng), sym(rng)));
    soup.v2.push_back(c + size * glm::vec3(sym(rng), sym(rng), sym(rng)));
  }
  return soup;
}

bool contains(const gpu::vec4& lo, const gpu::vec4& hi, const glm::vec3& p) {
  return lo.x <= p.x && p.x <= hi.x && lo.y <= p.y && p.y <= hi.y && lo.z <= p.z && p.z <= hi.z;
}

// Walks the layout from the root: each triangle of bvh.triangles in exactly one leaf, each child
// box containing its leaf's vertices or its node's child boxes, no reference out of range, and
// the deepest node at maxDepth. Returns a description of the first problem, or "".
std::string validateLayout(const Bvh& bvh, const BinaryBvh& binary) {
  std::vector<int> seen(bvh.triangles.size(), 0);
  std::vector<int> visited(binary.nodes.size(), 0);
  std::uint32_t deepest = 0;
  struct Entry { std::uint32_t node, depth; };
  std::vector<Entry> todo = {{0, 1}};
  while (!todo.empty()) {
    const Entry e = todo.back();
    todo.pop_back();
    if (e.node >= binary.nodes.size()) return "node reference out of range";
    if (visited[e.node]++) return "node reached twice";
    deepest = std::max(deepest, e.depth);
    const gpu::BvhBinaryNode& n = binary.nodes[e.node];
    const std::pair<gpu::vec4, gpu::vec4> boxes[2] = {{n.leftLo, n.leftHi}, {n.rightLo, n.rightHi}};
    const std::uint32_t refs[2] = {std::bit_cast<std::uint32_t>(n.leftLo.w), std::bit_cast<std::uint32_t>(n.leftHi.w)};
    for (int c = 0; c < 2; ++c) {
      const auto [lo, hi] = boxes[c];
      if (refs[c] == gpu::kInvalidIndex) {
        if (!(lo.x == kInf && hi.x == kInf)) return "an absent child whose box a ray can meet";
        continue;
      }
      if (isBinaryLeaf(refs[c])) {
        const std::uint32_t first = binaryLeafFirst(refs[c]), count = binaryLeafCount(refs[c]);
        if (count < 1 || count > gpu::kLeafMaxTriangles || first + count > bvh.triangles.size()) return "bad leaf";
        for (std::uint32_t t = first; t < first + count; ++t) {
          ++seen[t];
          for (const gpu::vec4* v : {&bvh.triangles[t].v0, &bvh.triangles[t].v1, &bvh.triangles[t].v2})
            if (!contains(lo, hi, glm::vec3(*v))) return "a leaf box misses a vertex of its triangle";
        }
        continue;
      }
      if (refs[c] <= e.node) return "a child before its parent";
      const gpu::BvhBinaryNode& child = binary.nodes[refs[c]];
      for (const gpu::vec4* corner : {&child.leftLo, &child.leftHi, &child.rightLo, &child.rightHi})
        if (corner->x != kInf && !contains(lo, hi, glm::vec3(*corner))) return "a child box outside its parent's";
      todo.push_back({refs[c], e.depth + 1});
    }
  }
  for (std::size_t t = 0; t < seen.size(); ++t)
    if (seen[t] != 1) return "triangle " + std::to_string(t) + " in " + std::to_string(seen[t]) + " leaves";
  for (int v : visited)
    if (v != 1) return "an unreachable node";
  if (deepest != binary.maxDepth) return "maxDepth " + std::to_string(binary.maxDepth) + ", deepest node " + std::to_string(deepest);
  return "";
}

// Random rays through the soup's box (some from inside it, some with zero direction components)
// traced over both layouts: identical hits (same t, triangle and barycentrics), same occlusion.
void expectSameAnswersAsTheWideTree(const Bvh& bvh, const BinaryBvh& binary, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.0f, 11.0f), dir(-1.0f, 1.0f), len(0.5f, 20.0f);
  int closestMismatches = 0, anyMismatches = 0, hits = 0;
  for (int i = 0; i < 20000; ++i) {
    Ray ray{{pos(rng), pos(rng), pos(rng)}, {dir(rng), dir(rng), dir(rng)}};
    if (i % 7 == 0) ray.direction[i % 3] = 0.0f;
    if (i % 2 == 0) ray.tmax = len(rng);
    const Hit wide = closestHit(bvh, ray), bin = closestHitBinary(bvh, binary, ray);
    hits += wide.hit();
    if (wide.primitive != bin.primitive || (wide.hit() && (wide.t != bin.t || wide.u != bin.u || wide.v != bin.v)))
      ++closestMismatches;
    if (anyHit(bvh, ray) != anyHitBinary(bvh, binary, ray)) ++anyMismatches;
  }
  EXPECT_EQ(closestMismatches, 0);
  EXPECT_EQ(anyMismatches, 0);
  EXPECT_GT(hits, 1000);
}

TEST(BinaryLayout, CoversEveryTriangleOnceWithContainingBoxes) {
  for (std::uint32_t seed : {1u, 2u, 3u}) {
    const TriangleSoup soup = randomSoup(seed == 1 ? 5000 : 300 * seed, seed);
    const Bvh bvh = build(soup);
    const BinaryBvh binary = binaryLayout(bvh);
    EXPECT_EQ(validateLayout(bvh, binary), "") << seed;
    // A wide node of k children makes k - 1 binary nodes.
    EXPECT_GT(binary.nodes.size(), bvh.nodes.size());
    EXPECT_GE(binary.maxDepth, bvh.stats.maxDepth);
  }
}

TEST(BinaryLayout, TraversalGivesTheWideTraversalsAnswers) {
  for (std::uint32_t seed : {4u, 5u}) {
    const TriangleSoup soup = randomSoup(seed == 4 ? 4000 : 700, seed);
    const Bvh bvh = build(soup);
    expectSameAnswersAsTheWideTree(bvh, binaryLayout(bvh), seed);
  }
  // With spatial splits a triangle lies in several wide leaves: several binary ones too.
  BuildOptions splits;
  splits.spatialSplitBudget = 0.5f;
  TriangleSoup slivers = randomSoup(1500, 6);
  for (std::size_t i = 0; i < slivers.size(); i += 5) slivers.v1[i] = glm::vec3(10.0f) - slivers.v0[i];
  const Bvh bvh = build(slivers, splits);
  ASSERT_GT(bvh.stats.spatialSplits, 0u);
  expectSameAnswersAsTheWideTree(bvh, binaryLayout(bvh), 6);
}

TEST(BinaryLayout, RefittedTreeDerivesAgainToTheMovedTriangles) {
  TriangleSoup soup = randomSoup(2000, 7);
  Bvh bvh = build(soup);
  for (std::size_t i = 0; i < soup.size(); i += 3) {
    soup.v0[i] += glm::vec3(0.5f, -0.25f, 0.0f);
    soup.v1[i] += glm::vec3(0.5f, -0.25f, 0.0f);
    soup.v2[i] += glm::vec3(0.5f, -0.25f, 0.0f);
  }
  refit(bvh, soup);
  const BinaryBvh binary = binaryLayout(bvh);
  EXPECT_EQ(validateLayout(bvh, binary), "");
  expectSameAnswersAsTheWideTree(bvh, binary, 7);
}

TEST(BinaryLayout, OneTriangleAndNoneMakeARootWithAbsentChildren) {
  TriangleSoup one;
  one.v0 = {{0, 0, 0}};
  one.v1 = {{1, 0, 0}};
  one.v2 = {{0, 1, 0}};
  const Bvh single = build(one);
  const BinaryBvh binary = binaryLayout(single);
  ASSERT_EQ(binary.nodes.size(), 1u);
  EXPECT_EQ(validateLayout(single, binary), "");
  const Hit h = closestHitBinary(single, binary, Ray{{0.25f, 0.25f, 1.0f}, {0, 0, -1}});
  EXPECT_EQ(h.primitive, 0u);
  EXPECT_EQ(h.t, 1.0f);

  const Bvh empty = build(TriangleSoup{});
  const BinaryBvh none = binaryLayout(empty);
  ASSERT_EQ(none.nodes.size(), 1u);
  EXPECT_EQ(validateLayout(empty, none), "");
  EXPECT_FALSE(closestHitBinary(empty, none, Ray{{0, 0, 1}, {0, 0, -1}}).hit());
  EXPECT_FALSE(anyHitBinary(empty, none, Ray{{0, 0, 1}, {0, 0, -1}}));
}

TEST(BinaryLayout, LeafReferencesRoundTripAndRejectWhatTheyCannotHold) {
  const std::uint32_t ref = binaryLeafRef(12345, 3);
  EXPECT_TRUE(isBinaryLeaf(ref));
  EXPECT_EQ(binaryLeafFirst(ref), 12345u);
  EXPECT_EQ(binaryLeafCount(ref), 3u);
  EXPECT_NE(ref, gpu::kInvalidIndex);
  EXPECT_THROW(binaryLeafRef(gpu::kBinaryLeafTexelMask + 1, 1), std::length_error);
  EXPECT_THROW(binaryLeafRef(0, 0), std::length_error);
  EXPECT_THROW(binaryLeafRef(0, gpu::kLeafMaxTriangles + 1), std::length_error);
}

} // namespace
} // namespace obscura::bvh
