// Refit: after some triangles move, the refitted BVH finds exactly what brute force over the moved
// triangles finds (closest hit and any hit), for a move of a few triangles and of a whole object.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/incremental_refit.h"

namespace obscura::bvh {
namespace {

TriangleSoup randomSoup(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), size(-0.1f, 0.1f);
  TriangleSoup soup;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    soup.v0.push_back(c);
    soup.v1.push_back(c + glm::vec3(size(rng), size(rng), size(rng)));
    soup.v2.push_back(c + glm::vec3(size(rng), size(rng), size(rng)));
  }
  return soup;
}

void expectMatchesBruteForce(const Bvh& bvh, const TriangleSoup& soup, std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-1.5f, 1.5f), dir(-1.0f, 1.0f);
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    Ray ray{.origin = glm::vec3(pos(rng), pos(rng), pos(rng)), .direction = glm::vec3(dir(rng), dir(rng), dir(rng))};
    const Hit expected = closestHitBruteForce(soup, ray), got = closestHit(bvh, ray);
    ASSERT_EQ(got.primitive, expected.primitive) << "ray " << i;
    if (expected.hit()) {
      ++hits;
      EXPECT_EQ(got.t, expected.t);
    }
    ray.tmax = 0.5f;
    EXPECT_EQ(anyHit(bvh, ray), closestHitBruteForce(soup, ray).hit()) << "ray " << i;
  }
  EXPECT_GT(hits, 100);
}

TEST(BvhRefit, MovedTrianglesAreFoundWhereTheyAreNow) {
  std::mt19937 rng(5);
  TriangleSoup soup = randomSoup(3000, rng);
  Bvh bvh = build(soup);
  // An "object": triangles 1000..1499 move together by a large offset, across the scene.
  for (std::size_t i = 1000; i < 1500; ++i)
    for (auto* v : {&soup.v0[i], &soup.v1[i], &soup.v2[i]}) *v += glm::vec3(0.9f, -0.4f, 0.3f);
  refit(bvh, soup);
  expectMatchesBruteForce(bvh, soup, rng);
}

TEST(BvhRefit, WithoutMovesRefitChangesNothing) {
  std::mt19937 rng(6);
  const TriangleSoup soup = randomSoup(500, rng);
  const Bvh built = build(soup);
  Bvh refitted = built;
  refit(refitted, soup);
  ASSERT_EQ(built.nodes.size(), refitted.nodes.size());
  EXPECT_EQ(std::memcmp(built.nodes.data(), refitted.nodes.data(), built.nodes.size() * sizeof(gpu::BvhNode)), 0);
}

// Triangles [first, last) of `soup` moved by `by`: the soup changed in place, and the moved ones
// (ids and their new vertices) as IncrementalRefit takes them.
struct Moved {
  std::vector<std::uint32_t> ids;
  TriangleSoup soup;
};
Moved moveRange(TriangleSoup& soup, std::uint32_t first, std::uint32_t last, glm::vec3 by) {
  Moved m;
  for (std::uint32_t i = first; i < last; ++i) {
    for (auto* v : {&soup.v0[i], &soup.v1[i], &soup.v2[i]}) *v += by;
    m.ids.push_back(i);
    m.soup.v0.push_back(soup.v0[i]);
    m.soup.v1.push_back(soup.v1[i]);
    m.soup.v2.push_back(soup.v2[i]);
  }
  return m;
}

// Refitting only the nodes above the moved triangles gives the tree a whole refit gives, byte for
// byte, move after move (one object moved twice, then another), in a fraction of the nodes.
TEST(BvhRefit, IncrementalRefitEqualsAWholeRefit) {
  std::mt19937 rng(7);
  TriangleSoup soup = randomSoup(3000, rng);
  Bvh whole = build(soup);
  Bvh incremental = whole;
  IncrementalRefit refitter(incremental);
  const struct {
    std::uint32_t first, last;
    glm::vec3 by;
  } moves[] = {{1000, 1040, {0.9f, -0.4f, 0.3f}}, {1000, 1040, {-0.2f, 0.1f, 0.0f}}, {2500, 2510, {0.0f, 0.5f, 0.0f}}};
  for (const auto& move : moves) {
    const Moved m = moveRange(soup, move.first, move.last, move.by);
    refit(whole, soup);
    const std::size_t nodes = refitter.refit(incremental, m.ids, m.soup).size();
    ASSERT_EQ(std::memcmp(whole.nodes.data(), incremental.nodes.data(), whole.nodes.size() * sizeof(gpu::BvhNode)), 0);
    ASSERT_EQ(std::memcmp(whole.triangles.data(), incremental.triangles.data(), whole.triangles.size() * sizeof(gpu::BvhTriangle)), 0);
    EXPECT_GT(nodes, 0u);
    EXPECT_LT(nodes, whole.nodes.size() / 4) << "most of the tree refitted for " << m.ids.size() << " triangles";
  }
  expectMatchesBruteForce(incremental, soup, rng);
}

// With spatial splits a triangle lies in several leaves, each with a clipped box: every copy is
// moved and the tree still finds exactly what brute force finds.
TEST(BvhRefit, IncrementalRefitMovesEveryCopyOfASplitTriangle) {
  std::mt19937 rng(8);
  TriangleSoup soup = randomSoup(2000, rng);
  for (std::size_t i = 0; i < 200; ++i) soup.v2[i] = soup.v0[i] + glm::vec3(0.8f, 0.6f, -0.7f); // long ones, worth splitting
  BuildOptions options;
  options.spatialSplitBudget = 0.3f;
  Bvh bvh = build(soup, options);
  ASSERT_GT(bvh.triangles.size(), soup.size()) << "no triangle was split";
  IncrementalRefit refitter(bvh);
  const Moved m = moveRange(soup, 0, 300, {0.3f, 0.2f, -0.4f});
  refitter.refit(bvh, m.ids, m.soup);
  expectMatchesBruteForce(bvh, soup, rng);
}

} // namespace
} // namespace obscura::bvh
