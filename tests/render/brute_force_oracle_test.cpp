// The traversal tests' oracle (test_scenes.h: bruteForce) culls by padded triangle boxes before
// its watertight tests; it must give bit for bit what the plain brute force over every triangle
// gives (bvh::closestHitBruteForce), on the rays where a cull could go wrong: through vertices and
// edges, along an axis (zero direction components), grazing a triangle's plane, from inside a
// box, limited by tmin and tmax, over triangles from 1e-4 to 3 units wide.
#include <bit>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

bvh::TriangleSoup soupOfGeometricSizes(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> position(-10.0f, 10.0f), offset(-1.0f, 1.0f), exponent(-4.0f, 0.5f);
  bvh::TriangleSoup soup;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 centre(position(rng), position(rng), position(rng));
    const float size = std::pow(10.0f, exponent(rng));
    soup.v0.push_back(centre + size * glm::vec3(offset(rng), offset(rng), offset(rng)));
    soup.v1.push_back(centre + size * glm::vec3(offset(rng), offset(rng), offset(rng)));
    soup.v2.push_back(centre + size * glm::vec3(offset(rng), offset(rng), offset(rng)));
  }
  // Axis-aligned triangles: flat boxes, which the padding must keep open.
  for (int axis = 0; axis < 3; ++axis) {
    glm::vec3 a(0.0f), b(0.0f), c(0.0f);
    a[(axis + 1) % 3] = -5.0f;
    b[(axis + 1) % 3] = 5.0f;
    c[(axis + 2) % 3] = 5.0f;
    a[axis] = b[axis] = c[axis] = 0.25f * static_cast<float>(axis + 1);
    soup.v0.push_back(a);
    soup.v1.push_back(b);
    soup.v2.push_back(c);
  }
  return soup;
}

std::vector<bvh::Ray> hardRays(const bvh::TriangleSoup& soup, std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> position(-12.0f, 12.0f), unit(-1.0f, 1.0f), fraction(0.0f, 1.0f);
  std::uniform_int_distribution<std::size_t> triangle(0, soup.size() - 1);
  std::vector<bvh::Ray> rays;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 origin(position(rng), position(rng), position(rng));
    const std::size_t t = triangle(rng);
    bvh::Ray ray{origin, glm::vec3(unit(rng), unit(rng), unit(rng))};
    switch (i % 6) {
    case 0: break;                                        // random
    case 1: ray.direction = soup.v0[t] - origin; break;    // through a vertex
    case 2: ray.direction = 0.5f * (soup.v1[t] + soup.v2[t]) - origin; break; // through an edge
    case 3: ray.direction = glm::vec3(0.0f); ray.direction[i % 3] = unit(rng) < 0 ? -1.0f : 1.0f; break; // along an axis
    case 4: { // from a triangle's corner along its own plane
      ray.origin = soup.v0[t];
      ray.direction = soup.v1[t] - soup.v0[t] + fraction(rng) * (soup.v2[t] - soup.v1[t]);
      break;
    }
    default: // limited to an interval
      ray.direction = (soup.v0[t] + soup.v1[t] + soup.v2[t]) / 3.0f - origin;
      ray.tmin = 0.5f * fraction(rng);
      ray.tmax = 0.5f + fraction(rng);
    }
    if (ray.direction == glm::vec3(0.0f)) ray.direction = glm::vec3(0.0f, 0.0f, 1.0f);
    rays.push_back(ray);
  }
  return rays;
}

TEST(BruteForceOracle, BoxCullKeepsThePlainBruteForcesAnswers) {
  const bvh::TriangleSoup soup = soupOfGeometricSizes(3000, 7);
  const std::vector<bvh::Ray> rays = hardRays(soup, 30000, 8);
  const std::vector<bvh::Hit> culled = bruteForce(soup, rays);
  std::size_t hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bvh::Hit plain = bvh::closestHitBruteForce(soup, rays[i]);
    hits += plain.hit();
    ASSERT_EQ(culled[i].primitive, plain.primitive) << "ray " << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(culled[i].t), std::bit_cast<std::uint32_t>(plain.t)) << "ray " << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(culled[i].u), std::bit_cast<std::uint32_t>(plain.u)) << "ray " << i;
    ASSERT_EQ(std::bit_cast<std::uint32_t>(culled[i].v), std::bit_cast<std::uint32_t>(plain.v)) << "ray " << i;
  }
  EXPECT_GT(hits, rays.size() / 3) << "most rays aim at a triangle";
}

} // namespace
} // namespace obscura::test
