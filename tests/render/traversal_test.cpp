// GPU traversal (shaders/lib/bvh.glsl through trace.comp) against brute force over all triangles:
// random soups, the Cornell box and modern-hall, >= 100k random rays each. Same triangle (ties by
// t, then primitive id) and t within 1e-5 relative. Also: the loop limiter cannot cut a traversal
// off unnoticed.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/wide_node.h"
#include "gpu_test.h"
#include "render/test_scenes.h"
#include "loop_limit_test.spv.h"
#include "bench/bench_rays.h"
#include "render/ray_tracer.h"
#include "core/error.h"
#include "render/scene_data/bvh_layout.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {

// Brute force on all cores: the oracle.

struct Comparison {
  std::size_t rays = 0, hits = 0;
  std::size_t hitMissDisagreements = 0;
  std::size_t tDisagreements = 0;        // |t_gpu - t_cpu| > 1e-5 relative
  std::size_t primitiveTies = 0;         // same t, other triangle (a shared edge or vertex)
  std::size_t barycentricDisagreements = 0; // same triangle, |u or v difference| > 1e-5
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
    else if (std::abs(g.u - b.u) > 1e-5f || std::abs(g.v - b.v) > 1e-5f) ++c.barycentricDisagreements;
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
  // The barycentrics are found again after the traversal loop (storedHit in shaders/lib/bvh.glsl).
  EXPECT_EQ(c.barycentricDisagreements, 0u) << what;
  EXPECT_GT(c.hits, 0u) << what;
}

class GpuTraversal : public GpuTest {
protected:
  Comparison traceAndCompare(const scene::Scene& scene, std::size_t count, std::uint64_t seed,
                             std::optional<render::TraceShape> shape = {}, const bvh::BuildOptions& options = {},
                             std::optional<render::Traversal> traversal = {}) {
    bvh::TriangleSoup soup = render::triangleSoup(scene);
    bvh::Bvh tree = bvh::build(soup, options);
    if (options.spatialSplitBudget > 0.0f) {
      EXPECT_GT(tree.stats.spatialSplits, 0u);
    }
    render::SceneBuffers buffers(context(), scene, tree, traversal);
    EXPECT_EQ(buffers.traversal(), traversal.value_or(render::Traversal::Wide)); // lavapipe's own: wide
    render::RayTracer tracer(context(), buffers, shape);
    auto rays = bench::closestBenchRays(scene.bounds, count, seed);
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

// A tree with spatial splits: triangles clipped into several leaves, each stored once per leaf.
// Long slivers crossing the soup make the builder use them.
TEST_F(GpuTraversal, TreeWithSpatialSplitsMatchesBruteForce) {
  bvh::TriangleSoup soup = randomSoup(2000, 3);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> pos(-10.0f, 10.0f);
  for (std::size_t i = 0; i < soup.size(); i += 8) {
    const glm::vec3 far(pos(rng), pos(rng), pos(rng));
    soup.v1[i] = far;
    soup.v2[i] = far + 0.02f * (soup.v0[i] - far);
  }
  bvh::BuildOptions options;
  options.spatialSplitBudget = 0.3f;
  expectAgreement(traceAndCompare(soupScene(soup), 100000, 3, {}, options), "spatial splits");
}

TEST_F(GpuTraversal, CornellBoxMatchesBruteForce) {
  scene::Scene s = scene::loadGltf(sharedScene("cornell-box/cornell-box.gltf"));
  expectAgreement(traceAndCompare(s, 200000, 11), "cornell-box");
}

TEST_F(GpuTraversal, ModernHallMatchesBruteForce) {
  scene::Scene s = scene::loadGltf(sharedScene("modern-hall/modern-hall.gltf"));
  expectAgreement(traceAndCompare(s, 100000, 12), "modern-hall");
}

// trace.comp's other shapes, run here on lavapipe: a GPU's (8 rays per invocation, workgroups of
// 32) and one ray per invocation straight through traverseBvh (kRaysPerLane = 1), and the BVH read
// from its buffer as an SSBO instead of through the texel view: the same answers as the brute
// force, like the lavapipe shape above.
TEST_F(GpuTraversal, GpuAndOneRayPerInvocationShapesMatchBruteForce) {
  scene::Scene soup = soupScene(randomSoup(3000, 1));
  expectAgreement(traceAndCompare(soup, 100000, 1, render::TraceShape::forGpu()), "random soup, GPU shape");
  expectAgreement(traceAndCompare(soup, 100000, 1, render::TraceShape{128, 1}), "random soup, one ray per invocation");
  render::TraceShape fromStorage = render::TraceShape::forGpu();
  fromStorage.bvhItemsFromStorage = true;
  expectAgreement(traceAndCompare(soup, 100000, 1, fromStorage), "random soup, GPU shape, BVH from an SSBO");
}

// The binary layout with both its loops (render/scene_data/bvh_layout.h: a GPU's traversal), run here
// on lavapipe: the same closest hits as the brute force, the same occlusion as the CPU's any hit.
TEST_F(GpuTraversal, BinaryLayoutMatchesBruteForceAndCpuAnyHit) {
  const scene::Scene soup = soupScene(randomSoup(3000, 1));
  const scene::Scene cornell = scene::loadGltf(sharedScene("cornell-box/cornell-box.gltf"));
  bvh::BuildOptions splits;
  splits.spatialSplitBudget = 0.3f;
  // Each loop on a random soup, and (split between them, to keep the test short) a tree with
  // spatial splits, the Cornell box and the cull on pop (bench-rays --cull-on-pop).
  expectAgreement(traceAndCompare(soup, 100000, 1, {}, {}, render::Traversal::Binary), "random soup, binary");
  expectAgreement(traceAndCompare(soup, 100000, 2, {}, splits, render::Traversal::Binary), "spatial splits, binary");
  expectAgreement(traceAndCompare(soup, 100000, 1, {}, {}, render::Traversal::BinaryWhileWhile),
                  "random soup, binary-while-while");
  expectAgreement(traceAndCompare(cornell, 100000, 11, {}, {}, render::Traversal::BinaryWhileWhile),
                  "cornell-box, binary-while-while");
  render::TraceShape culling = render::TraceShape::forBinary();
  culling.binaryCullOnPop = true;
  expectAgreement(traceAndCompare(soup, 100000, 4, culling, splits, render::Traversal::BinaryWhileWhile),
                  "cull on pop, binary-while-while");
  for (const render::Traversal traversal : {render::Traversal::Binary, render::Traversal::BinaryWhileWhile}) {
    const std::string name = render::traversalName(traversal);

    const bvh::Bvh tree = bvh::build(render::triangleSoup(cornell));
    render::SceneBuffers buffers(context(), cornell, tree, traversal);
    render::RayTracer tracer(context(), buffers);
    EXPECT_EQ(tracer.shape().raysPerLane, 1u);
    const auto rays = bench::shadowBenchRays(cornell.bounds, 100000, 5);
    const auto result = tracer.trace(rays, render::TraceMode::Any);
    std::size_t disagreements = 0, occluded = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const bvh::Ray r{glm::vec3(rays[i].origin), glm::vec3(rays[i].direction), rays[i].origin.w, rays[i].direction.w};
      const bool cpu = bvh::anyHit(tree, r);
      occluded += cpu;
      disagreements += cpu != (result.hits[i].primitive != gpu::kInvalidIndex);
    }
    EXPECT_EQ(disagreements, 0u) << name;
    EXPECT_GT(occluded, rays.size() / 10) << name;
    EXPECT_EQ(buffers.truncatedTraversals(), 0u) << name;
  }
}

// Several rays per invocation over the binary layout: trace.comp's refilling loop
// (traverseBinaryStream), in lavapipe's shape and a GPU's.
TEST_F(GpuTraversal, BinaryRefillingShapesMatchBruteForce) {
  const scene::Scene soup = soupScene(randomSoup(3000, 1));
  for (const render::TraceShape shape : {render::TraceShape::forCpu(), render::TraceShape::forGpu()})
    expectAgreement(traceAndCompare(soup, 100000, 3, shape, {}, render::Traversal::Binary),
                    ("random soup, binary, " + std::to_string(shape.raysPerLane) + " rays per invocation").c_str());
}

// Repeats traced back to back in one submission (bench-rays on a GPU) each give a time and the
// same hits as one trace.
TEST_F(GpuTraversal, RepeatedTraceTimesEachRepeatAndKeepsTheHits) {
  scene::Scene soup = soupScene(randomSoup(500, 3));
  bvh::Bvh tree = bvh::build(render::triangleSoup(soup));
  render::SceneBuffers buffers(context(), soup, tree);
  render::RayTracer tracer(context(), buffers);
  auto rays = bench::closestBenchRays(soup.bounds, 5000, 3);
  auto once = tracer.trace(rays, render::TraceMode::Closest);
  auto repeated = tracer.traceRepeated(rays, render::TraceMode::Closest, 3);
  ASSERT_EQ(repeated.repeatGpuMs.size(), 3u);
  for (double ms : repeated.repeatGpuMs) EXPECT_GT(ms, 0.0);
  ASSERT_EQ(repeated.hits.size(), once.hits.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_EQ(repeated.hits[i].primitive, once.hits[i].primitive) << i;
    ASSERT_EQ(repeated.hits[i].t, once.hits[i].t) << i;
  }
}

TEST_F(GpuTraversal, ShadowRaysMatchCpuAnyHit) {
  scene::Scene s = scene::loadGltf(sharedScene("cornell-box/cornell-box.gltf"));
  bvh::TriangleSoup soup = render::triangleSoup(s);
  bvh::Bvh tree = bvh::build(soup);
  render::SceneBuffers buffers(context(), s, tree);
  render::RayTracer tracer(context(), buffers);
  auto rays = bench::shadowBenchRays(s.bounds, 100000, 5);
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

// The wide loop and the binary layout's one loop, which counts its passes as the wide loop does
// (lavapipe's loop limiter cannot cut either off unnoticed).
TEST_F(GpuTraversal, LongTraversalIsReportedNotTruncatedSilently) {
  for (const render::Traversal traversal : {render::Traversal::Wide, render::Traversal::Binary}) {
    for (std::size_t n : {20000u, 70000u}) {
      scene::Scene s = stackedMisses(n);
      bvh::Bvh tree = bvh::build(render::triangleSoup(s));
      render::SceneBuffers buffers(context(), s, tree, traversal);
      render::RayTracer tracer(context(), buffers);
      std::vector<gpu::GpuRay> rays(8, gpu::GpuRay{glm::vec4(0, 0, -1, 0), glm::vec4(0, 0, 1, INFINITY)});
      auto result = tracer.trace(rays, render::TraceMode::Closest, true);
      const std::string what = render::traversalName(traversal) + ", " + std::to_string(n) + " triangles";
      if (n == 20000) {
        // Every triangle is tested: at least n passes, and still a clean miss.
        EXPECT_EQ(result.hits[0].primitive, gpu::kInvalidIndex) << what;
        EXPECT_GE(result.steps[0], n) << what;
        EXPECT_LT(result.steps[0], gpu::kMaxTraversalSteps) << what;
        EXPECT_EQ(buffers.truncatedTraversals(), 0u) << what;
      } else {
        // Too long: the traversal stops itself, says so per ray and in the status counter.
        EXPECT_EQ(result.hits[0].primitive, gpu::kTruncatedHit) << what;
        EXPECT_EQ(result.steps[0], gpu::kMaxTraversalSteps) << what;
        EXPECT_EQ(buffers.truncatedTraversals(), rays.size()) << what;
      }
    }
  }
}

// Stacks deeper than the registers hold (gpu::kBvhRegisterStack) take the second, array-stack
// loop of shaders/lib/bvh.glsl. combBvh (test_scenes.h) makes every level push: a ray along +x
// descends the spine first and leaves one rib group per level on the stack. Ribs hold triangles
// that miss the x axis; the spine ends in the one triangle the rays hit.
struct Comb {
  bvh::TriangleSoup soup;
  bvh::Bvh tree;
};

Comb comb(std::uint32_t levels) {
  Comb c;
  auto add = [&](glm::vec3 a, glm::vec3 b, glm::vec3 d) {
    c.soup.v0.push_back(a);
    c.soup.v1.push_back(b);
    c.soup.v2.push_back(d);
  };
  for (std::uint32_t k = 0; k < levels; ++k) {
    const float x = static_cast<float>(k + 1);
    add({x, -0.9f, 1.1f}, {x, 1.1f, 1.1f}, {x, 1.1f, -0.9f}); // rib k: misses the axis
  }
  add({levels + 5.0f, -1.0f, -1.0f}, {levels + 5.0f, 3.0f, -1.0f}, {levels + 5.0f, -1.0f, 3.0f});
  c.tree = combBvh(c.soup);
  return c;
}

// Rays along +x through the comb's spine (jittered within the ribs' gap).
std::vector<gpu::GpuRay> combRays() {
  std::vector<gpu::GpuRay> rays;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
  for (int i = 0; i < 64; ++i)
    rays.push_back({glm::vec4(0.5f, jitter(rng), jitter(rng), 0.0f), glm::vec4(1.0f, 0.0f, 0.0f, INFINITY)});
  return rays;
}

// The comb's closest hits match the brute force (the spine's last triangle), its any hits end at
// that triangle's plane; returns each ray's loop passes.
std::vector<std::uint32_t> expectCombHits(render::RayTracer& tracer, const Comb& c, std::uint32_t levels) {
  std::vector<gpu::GpuRay> rays = combRays();
  auto result = tracer.trace(rays, render::TraceMode::Closest, true);
  auto cpu = bruteForce(c.soup, rays);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(result.hits[i].primitive, cpu[i].primitive) << i;
    EXPECT_EQ(result.hits[i].t, cpu[i].t) << i;
  }
  EXPECT_EQ(result.hits[0].primitive, levels);
  // Any hit: not occluded short of the last triangle's plane, occluded beyond it.
  for (auto& r : rays) r.direction.w = static_cast<float>(levels) + 4.0f; // the hit is at t = levels + 4.5
  auto blocked = tracer.trace(rays, render::TraceMode::Any);
  for (auto& r : rays) r.direction.w = INFINITY;
  auto open = tracer.trace(rays, render::TraceMode::Any);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(blocked.hits[i].primitive, gpu::kInvalidIndex) << i;
    EXPECT_EQ(open.hits[i].primitive, levels) << i;
  }
  return result.steps;
}

TEST_F(GpuTraversal, DeepStackMatchesBruteForce) {
  const std::uint32_t levels = 20;
  static_assert(20 > gpu::kBvhCompactStackMaxDepth && 20 < gpu::kBvhStackSize);
  Comb c = comb(levels);
  scene::Scene s = soupScene(c.soup);
  render::SceneBuffers buffers(context(), s, c.tree);
  ASSERT_EQ(buffers.compactStackVectors(), 0u);
  render::RayTracer tracer(context(), buffers);
  const std::vector<std::uint32_t> steps = expectCombHits(tracer, c, levels);
  // Every node is visited: the spine and the ribs (the overflow restarts from the root).
  for (std::size_t i = 0; i < steps.size(); ++i) EXPECT_GE(steps[i], 2 * levels) << i;
  EXPECT_EQ(buffers.truncatedTraversals(), 0u);
}

// The compact stack (kSpecConstantCompactStack) has no second loop: the deepest BVH a stack of v
// uvec4 registers accepts must never overflow it. The comb of depth 4 v + 2 pushes one entry per
// level below the root, 4 v in all, and still finds every hit, through trace.comp's refilling
// loop and through traverseBvh (one ray per invocation, as the passes trace). One level deeper
// needs a register more, and a kernel with v refuses that BVH; beyond 4 registers (depth 18) the
// general stack takes it.
TEST_F(GpuTraversal, CompactStackHoldsTheDeepestBvhItAccepts) {
  for (std::uint32_t v = 1; v <= gpu::kBvhCompactStackVectors; ++v) {
    const std::uint32_t levels = 4 * v + 1;
    Comb c = comb(levels);
    ASSERT_EQ(c.tree.stats.maxDepth, 4 * v + 2);
    scene::Scene s = soupScene(c.soup);
    render::SceneBuffers buffers(context(), s, c.tree);
    ASSERT_EQ(buffers.compactStackVectors(), v);
    for (const render::TraceShape shape : {render::TraceShape::forCpu(), render::TraceShape{128, 1}}) {
      render::RayTracer tracer(context(), buffers, shape, v);
      // The ribs' triangles miss the rays, so a rib dropped from the stack would not change the
      // hits: every one of the 2 levels + 1 nodes must be visited, one per pass at most.
      for (const std::uint32_t steps : expectCombHits(tracer, c, levels)) EXPECT_GE(steps, 2 * levels + 1) << v;
    }
    EXPECT_EQ(buffers.truncatedTraversals(), 0u);

    Comb deeper = comb(levels + 1);
    scene::Scene deeperScene = soupScene(deeper.soup);
    render::SceneBuffers deeperBuffers(context(), deeperScene, deeper.tree);
    EXPECT_EQ(deeperBuffers.compactStackVectors(), v < gpu::kBvhCompactStackVectors ? v + 1 : 0u);
    EXPECT_THROW(render::RayTracer(context(), deeperBuffers, {}, v), std::logic_error);
  }
  static_assert(4 * gpu::kBvhCompactStackVectors + 2 == gpu::kBvhCompactStackMaxDepth);
}

// The binary traversals on the comb, whose every level pushes: the same hits as the brute force.
// A comb deeper than the binary stack (kBinaryStackSize) cannot have the binary layout: asked for,
// it is refused with a DeviceError; the device's choice falls back to the wide one.
TEST_F(GpuTraversal, BinaryLayoutHoldsDeepStacksAndRefusesTreesDeeperThanItsStack) {
  const std::uint32_t levels = 40;
  Comb c = comb(levels);
  scene::Scene s = soupScene(c.soup);
  for (const render::Traversal traversal : {render::Traversal::Binary, render::Traversal::BinaryWhileWhile}) {
    render::SceneBuffers buffers(context(), s, c.tree, traversal);
    render::RayTracer tracer(context(), buffers);
    expectCombHits(tracer, c, levels);
    EXPECT_EQ(buffers.truncatedTraversals(), 0u);
  }
  Comb deep = comb(gpu::kBinaryStackSize + 4);
  scene::Scene deepScene = soupScene(deep.soup);
  EXPECT_FALSE(render::binaryBvhTexels(deep.tree).has_value());
  EXPECT_THROW(render::SceneBuffers(context(), deepScene, deep.tree, render::Traversal::Binary), DeviceError);
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
    context().submitAndWait([&](const vk::raii::CommandBuffer& cmd) { kernel.dispatch(cmd, 1, 1, 1, push); });
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
