// Inserting triangles into a built BVH (insert.h): after the insert and the refit above it, the
// tree finds exactly what brute force over the grown soup finds, the new triangles included, and
// the tree's depth is unchanged.
#include <random>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/incremental_refit.h"
#include "bvh/insert.h"

namespace obscura::bvh {
namespace {

TEST(BvhInsert, InsertedTrianglesAreFoundAndNothingElseChanges) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), size(-0.1f, 0.1f), dir(-1.0f, 1.0f);
  TriangleSoup soup;
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    soup.v0.push_back(c);
    soup.v1.push_back(c + glm::vec3(size(rng), size(rng), size(rng)));
    soup.v2.push_back(c + glm::vec3(size(rng), size(rng), size(rng)));
  }
  Bvh bvh = build(soup);
  const std::uint32_t stack = compactStackVectors(bvh);
  const std::size_t nodes = bvh.nodes.size();
  // Three quads (two triangles each), one of them outside everything built.
  for (const glm::vec3 corner : {glm::vec3(0.1f, 0.2f, -0.3f), glm::vec3(-0.7f, 0.5f, 0.6f), glm::vec3(1.5f, 1.5f, 1.5f)}) {
    const glm::vec3 u(0.3f, 0.0f, 0.05f), v(0.0f, 0.25f, 0.1f);
    TriangleSoup quad;
    quad.v0 = {corner, corner};
    quad.v1 = {corner + u, corner + u + v};
    quad.v2 = {corner + u + v, corner + v};
    const std::vector<std::uint32_t> ids{static_cast<std::uint32_t>(soup.size()), static_cast<std::uint32_t>(soup.size() + 1)};
    for (std::size_t k = 0; k < 2; ++k) {
      soup.v0.push_back(quad.v0[k]);
      soup.v1.push_back(quad.v1[k]);
      soup.v2.push_back(quad.v2[k]);
    }
    ASSERT_TRUE(insertTriangles(bvh, ids, quad));
    IncrementalRefit(bvh).refit(bvh, ids, quad);
    // Rays at the quad's triangles and at random.
    int quadHits = 0;
    for (int i = 0; i < 1500; ++i) {
      Ray ray{.origin = glm::vec3(pos(rng), pos(rng), pos(rng)) * 1.5f, .direction = glm::vec3(dir(rng), dir(rng), dir(rng))};
      if (i % 2 == 0) ray.direction = corner + 0.3f * u + 0.3f * v + glm::vec3(size(rng), size(rng), size(rng)) - ray.origin;
      const Hit expected = closestHitBruteForce(soup, ray), got = closestHit(bvh, ray);
      ASSERT_EQ(got.primitive, expected.primitive) << "ray " << i;
      if (expected.hit()) {
        EXPECT_EQ(got.t, expected.t);
      }
      quadHits += expected.primitive == ids[0] || expected.primitive == ids[1];
      ray.tmax = 0.7f;
      ASSERT_EQ(anyHit(bvh, ray), closestHitBruteForce(soup, ray).hit()) << "ray " << i;
    }
    EXPECT_GT(quadHits, 25);
  }
  EXPECT_EQ(bvh.nodes.size(), nodes) << "no node added: the tree is as deep as before";
  EXPECT_EQ(compactStackVectors(bvh), stack) << "the traversal stack the kernels are specialised for";
}

} // namespace
} // namespace obscura::bvh
