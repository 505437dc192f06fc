// Refit: after some triangles move, the refitted BVH finds exactly what brute force over the moved
// triangles finds (closest hit and any hit), for a move of a few triangles and of a whole object.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "bvh/bvh.h"

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

} // namespace
} // namespace obscura::bvh
