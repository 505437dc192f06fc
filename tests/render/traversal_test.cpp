// GPU traversal (shaders/lib/bvh.glsl through trace.comp) against brute force over all triangles:
// random soups, the Cornell box and modern-hall, >= 100k random rays each. Same triangle (ties by
// t, then primitive id) and t within 1e-5 relative. Also: the loop limiter cannot cut a traversal
// off unnoticed.
#include <algorithm>
#include <cmath>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/test_scenes.h"
#include "loop_limit_test.spv.h"
#include "bench/bench_rays.h"
#include "bench/ray_tracer.h"
#include "render/scene/scene_buffers.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {

// Brute force on all cores: the oracle.

struct Comparison {
  std::size_t rays = 0, hits = 0;
  std::size_t hitMissDisagreements = 0;
  std::size_t tDisagreements = 0;        // |t_gpu - t_cpu| > 1e-5 relative
  std::size_t primitiveTies = 0;         // same t, other triangle (a shared edge or vertex)
};

Comparison compare(const std::vector<gpu::GpuHit>& gpuHits, const std::vector<bvh::Hit>& cpuHits) {
  Comparison c;
  c.rays = gpuHits.size();
  for (std::size_t i = 0; i < gpuHits.size(); ++i) {
    const auto& g = gpuHits[i];
    const auto& b = cpuHits[i];
    bool gpuHit = g.primitive != gpu::kInvalidIndex;
    c.hits += b.hit();
    if (gpuHit != b.hit()) {
      ++c.hitMissDisagreements;
      continue;
    }
    if (!gpuHit) continue;
    if (std::abs(g.t - b.t) > 1e-5f * std::max(1.0f, std::abs(b.t))) ++c.tDisagreements;
    else if (g.primitive != b.primitive) ++c.primitiveTies;
  }
  return c;
}

void expectAgreement(const Comparison& c, const char* what) {
  EXPECT_GE(c.rays, 100000u) << what;
  EXPECT_EQ(c.hitMissDisagreements, 0u) << what;
  EXPECT_EQ(c.tDisagreements, 0u) << what;
  // Two triangles at the same t differ only for rays through a shared edge or vertex, where the
  // CPU and GPU may round the edge test differently (fused multiply-adds): at most 1 in 10^4.
  EXPECT_LE(c.primitiveTies, c.rays / 10000) << what;
  EXPECT_GT(c.hits, 0u) << what;
}

class GpuTraversal : public GpuTest {
protected:
  Comparison traceAndCompare(const scene::Scene& scene, std::size_t count, std::uint64_t seed) {
    bvh::TriangleSoup soup = render::triangleSoup(scene);
    bvh::Bvh tree = bvh::build(soup);
    render::SceneBuffers buffers(context(), scene, tree);
    render::RayTracer tracer(context(), buffers);
    auto rays = render::closestBenchRays(scene.bounds, count, seed);
    auto result = tracer.trace(rays, render::TraceMode::Closest);
    EXPECT_EQ(buffers.truncatedTraversals(), 0u);
    return compare(result.hits, bruteForce(soup, rays));
  }
};


bvh::TriangleSoup randomSoup(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-10.0f, 10.0f), size(-1.0f, 1.0f), scale(-4.0f, 0.5f);
  bvh::TriangleSoup soup;
  for (std::size_t i = 0; i < n; ++i) {
    glm::vec3 c(pos(rng), pos(rng), pos(rng));
    float s = std::pow(10.0f, scale(rng)); // sizes from 1e-4 to 3: some tiny
    soup.v0.push_back(c + s * glm::vec3(size(rng), size(rng), size(rng)));
    soup.v1.push_back(c + s * glm::vec3(size(rng), size(rng), size(rng)));
    soup.v2.push_back(c + s * glm::vec3(size(rng), size(rng), size(rng)));
  }
  return soup;
}

TEST_F(GpuTraversal, RandomSoupsMatchBruteForce) {
  for (std::uint32_t seed : {1u, 2u}) {
    scene::Scene s = soupScene(randomSoup(seed == 1 ? 3000 : 500, seed));
    expectAgreement(traceAndCompare(s, 100000, seed), "random soup");
  }
}

TEST_F(GpuTraversal, CornellBoxMatchesBruteForce) {
  scene::Scene s = scene::loadGltf(sharedScene("cornell-box/cornell-box.gltf"));
  expectAgreement(traceAndCompare(s, 200000, 11), "cornell-box");
}

TEST_F(GpuTraversal, ModernHallMatchesBruteForce) {
  scene::Scene s = scene::loadGltf(sharedScene("modern-hall/modern-hall.gltf"));
  expectAgreement(traceAndCompare(s, 100000, 12), "modern-hall");
}

TEST_F(GpuTraversal, ShadowRaysMatchCpuAnyHit) {
  scene::Scene s = scene::loadGltf(sharedScene("cornell-box/cornell-box.gltf"));
  bvh::TriangleSoup soup = render::triangleSoup(s);
  bvh::Bvh tree = bvh::build(soup);
  render::SceneBuffers buffers(context(), s, tree);
  render::RayTracer tracer(context(), buffers);
  auto rays = render::shadowBenchRays(s.bounds, 100000, 5);
  auto result = tracer.trace(rays, render::TraceMode::Any);
  std::size_t disagreements = 0, occluded = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    bvh::Ray r{glm::vec3(rays[i].origin), glm::vec3(rays[i].direction), rays[i].origin.w, rays[i].direction.w};
    bool cpu = bvh::anyHit(tree, r);
    occluded += cpu;
    disagreements += cpu != (result.hits[i].primitive != gpu::kInvalidIndex);
  }
  EXPECT_EQ(disagreements, 0u);
  EXPECT_GT(occluded, rays.size() / 10);
}

// A ray that passes through the boxes of every node but hits no triangle: n triangles stacked
// along +z, each missing the z axis by 0.1 while its box contains it. The traversal must visit
// them all, so its step count is known.
scene::Scene stackedMisses(std::size_t n) {
  bvh::TriangleSoup soup;
  for (std::size_t i = 0; i < n; ++i) {
    float z = static_cast<float>(i);
    soup.v0.push_back({-0.9f, 1.1f, z});
    soup.v1.push_back({1.1f, 1.1f, z});
    soup.v2.push_back({1.1f, -0.9f, z});
  }
  return soupScene(soup);
}

TEST_F(GpuTraversal, LongTraversalIsReportedNotTruncatedSilently) {
  for (std::size_t n : {20000u, 70000u}) {
    scene::Scene s = stackedMisses(n);
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    render::SceneBuffers buffers(context(), s, tree);
    render::RayTracer tracer(context(), buffers);
    std::vector<gpu::GpuRay> rays(8, gpu::GpuRay{glm::vec4(0, 0, -1, 0), glm::vec4(0, 0, 1, INFINITY)});
    auto result = tracer.trace(rays, render::TraceMode::Closest, true);
    if (n == 20000) {
      // Every triangle is tested: at least n passes, and still a clean miss.
      EXPECT_EQ(result.hits[0].primitive, gpu::kInvalidIndex);
      EXPECT_GE(result.steps[0], n);
      EXPECT_LT(result.steps[0], gpu::kMaxTraversalSteps);
      EXPECT_EQ(buffers.truncatedTraversals(), 0u);
    } else {
      // Too long: the traversal stops itself, says so per ray and in the status counter.
      EXPECT_EQ(result.hits[0].primitive, gpu::kTruncatedHit);
      EXPECT_EQ(result.steps[0], gpu::kMaxTraversalSteps);
      EXPECT_EQ(buffers.truncatedTraversals(), rays.size());
    }
  }
}

// Stacks deeper than the registers hold (gpu::kBvhRegisterStack) take the second, array-stack
// loop of shaders/lib/bvh.glsl. Triangles at x = 2^i make binned SAH peel off the farthest one
// per level, a chain of depth ~n; a ray along +x overlaps every box, so it pushes at every level.
// All but the last triangle miss the x axis (their boxes contain it).
TEST_F(GpuTraversal, DeepStackMatchesBruteForce) {
  const int n = 100;
  bvh::TriangleSoup soup;
  for (int i = 0; i < n; ++i) {
    float x = std::ldexp(1.0f, i);
    if (i + 1 < n) {
      soup.v0.push_back({x, -0.9f, 1.1f});
      soup.v1.push_back({x, 1.1f, 1.1f});
      soup.v2.push_back({x, 1.1f, -0.9f});
    } else {
      soup.v0.push_back({x, -1.0f, -1.0f});
      soup.v1.push_back({x, 3.0f, -1.0f});
      soup.v2.push_back({x, -1.0f, 3.0f});
    }
  }
  scene::Scene s = soupScene(soup);
  bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  ASSERT_GT(tree.stats.maxDepth, gpu::kBvhRegisterStack + 2) << "the scene no longer exercises the deep-stack path";
  render::SceneBuffers buffers(context(), s, tree);
  render::RayTracer tracer(context(), buffers);
  std::vector<gpu::GpuRay> rays;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
  for (int i = 0; i < 64; ++i)
    rays.push_back({glm::vec4(0.5f, jitter(rng), jitter(rng), 0.0f), glm::vec4(1.0f, 0.0f, 0.0f, INFINITY)});
  auto result = tracer.trace(rays, render::TraceMode::Closest, true);
  auto cpu = bruteForce(render::triangleSoup(s), rays);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(result.hits[i].primitive, cpu[i].primitive) << i;
    EXPECT_EQ(result.hits[i].t, cpu[i].t) << i;
  }
  EXPECT_EQ(result.hits[0].primitive, static_cast<std::uint32_t>(n - 1));
  // Any hit: not occluded short of the last triangle's plane, occluded beyond it.
  for (auto& r : rays) r.direction.w = std::ldexp(1.0f, n - 1) - 1.0f;
  auto blocked = tracer.trace(rays, render::TraceMode::Any);
  for (auto& r : rays) r.direction.w = INFINITY;
  auto open = tracer.trace(rays, render::TraceMode::Any);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(blocked.hits[i].primitive, gpu::kInvalidIndex) << i;
    EXPECT_EQ(open.hits[i].primitive, static_cast<std::uint32_t>(n - 1)) << i;
  }
  EXPECT_EQ(buffers.truncatedTraversals(), 0u);
}

class LoopLimiter : public GpuTest {};

TEST_F(LoopLimiter, TraversalBudgetStaysBelowTheDriverLimit) {
  using Usage = vk::BufferUsageFlagBits;
  gpu::Kernel kernel(context(), {.name = "loop_limit_test", .spirv = kSpirv_loop_limit_test,
                                 .bindings = {gpu::BindingKind::StorageBuffer}, .pushConstantBytes = 16});
  gpu::Buffer counts(context(), 8 * 4, Usage::eStorageBuffer, "test.counts");
  kernel.bind(0, counts);
  auto run = [&](std::uint32_t n) {
    glm::uvec4 push(n, 0, 0, 0);
    context().submitAndWait([&](const vk::raii::CommandBuffer& cmd) { kernel.dispatch(cmd, 1, 1, 1, &push); });
    return counts.download<std::uint32_t>(context())[0];
  };
  // Our own budget always runs to completion...
  EXPECT_EQ(run(gpu::kMaxTraversalSteps), gpu::kMaxTraversalSteps);
  // ...while a longer loop is silently cut off on lavapipe (and must not be on other drivers).
  std::uint32_t long_ = run(100000);
  if (context().info().isLavapipe) {
    EXPECT_LT(long_, 100000u) << "lavapipe no longer limits loops: kMaxTraversalSteps could be raised";
  } else {
    EXPECT_EQ(long_, 100000u);
  }
}

} // namespace
} // namespace obscura::test
