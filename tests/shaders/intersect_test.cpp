// The production intersect.glsl against its CPU twin (host/bvh/triangle_intersect.cpp): random
// triangles, edge and vertex hits, rays parallel to the triangle, zero direction components.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "box_test.spv.h"
#include "bvh/triangle_intersect.h"
#include "gpu/buffer.h"
#include "gpu/kernel.h"
#include "gpu_test.h"
#include "shared/host_device.h"
#include "intersect_test.spv.h"
#include "render/scene_data/scene_buffers.h"
#include "shaders/shader_runner.h"

namespace obscura::test {
namespace {

struct IntersectCase {
  gpu::GpuRay ray;
  glm::vec4 v0, v1, v2;
};
static_assert(sizeof(IntersectCase) == 80);

struct CpuResult {
  bool hit;
  float t, u, v;
};

CpuResult cpuIntersect(const IntersectCase& c) {
  auto r = bvh::prepareWatertightRay(glm::vec3(c.ray.origin), glm::vec3(c.ray.direction));
  CpuResult out{};
  out.hit = bvh::intersectTriangle(r, glm::vec3(c.v0), glm::vec3(c.v1), glm::vec3(c.v2), c.ray.origin.w,
                                   c.ray.direction.w, out.t, out.u, out.v);
  return out;
}

IntersectCase makeCase(glm::vec3 o, glm::vec3 d, glm::vec3 a, glm::vec3 b, glm::vec3 c, float tmin = 0.0f,
                       float tmax = INFINITY) {
  return {.ray = {glm::vec4(o, tmin), glm::vec4(d, tmax)}, .v0 = glm::vec4(a, 0), .v1 = glm::vec4(b, 0), .v2 = glm::vec4(c, 0)};
}

// Relative agreement of t: both sides run the same float algorithm, but a GPU compiler may fuse
// multiply-adds, so allow a few ulps (1e-5 relative, the tolerance).
void expectSame(const IntersectCase& c, const CpuResult& cpu, const glm::vec4& gpu, std::size_t i) {
  ASSERT_EQ(cpu.hit, gpu.x != 0.0f) << "case " << i;
  if (!cpu.hit) return;
  EXPECT_NEAR(gpu.y, cpu.t, 1e-5f * std::max(1.0f, std::abs(cpu.t))) << "case " << i;
  EXPECT_NEAR(gpu.z, cpu.u, 1e-4f) << "case " << i;
  EXPECT_NEAR(gpu.w, cpu.v, 1e-4f) << "case " << i;
  (void)c;
}

class IntersectShader : public GpuTest {};

TEST_F(IntersectShader, RandomTrianglesMatchCpu) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<IntersectCase> cases;
  for (int i = 0; i < 100000; ++i) {
    glm::vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    glm::vec3 o(3 * u(rng), 3 * u(rng), 3 * u(rng));
    // Aim at a random point of the triangle's neighbourhood so about half the rays hit.
    float s = 1.2f * std::abs(u(rng)), t = 1.2f * std::abs(u(rng));
    glm::vec3 target = a + s * (b - a) + t * (c - a) * 0.5f;
    cases.push_back(makeCase(o, target - o, a, b, c));
  }
  auto gpu = runCases<IntersectCase, glm::vec4>(context(), kSpirv_intersect_test, cases);
  std::size_t hits = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    CpuResult cpu = cpuIntersect(cases[i]);
    hits += cpu.hit;
    expectSame(cases[i], cpu, gpu[i], i);
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(hits, cases.size() / 5); // the test exercises hits, not only misses
  EXPECT_LT(hits, cases.size() * 4 / 5);
}

TEST_F(IntersectShader, EdgesVerticesParallelAndAxisRays) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  std::vector<IntersectCase> cases = {
      makeCase({0.25f, 0.25f, 1}, {0, 0, -1}, a, b, c),  // interior, axis-aligned (zero x, y)
      makeCase({0.5f, 0.0f, 1}, {0, 0, -1}, a, b, c),    // on edge ab
      makeCase({0.5f, 0.5f, 1}, {0, 0, -1}, a, b, c),    // on edge bc (hypotenuse)
      makeCase({0, 0, 1}, {0, 0, -1}, a, b, c),          // on vertex a
      makeCase({1, 0, 1}, {0, 0, -1}, a, b, c),          // on vertex b
      makeCase({-0.5f, 0.25f, 0}, {1, 0, 0}, a, b, c),   // in the triangle's plane: parallel
      makeCase({0.25f, 0.25f, 1}, {1, 0, 0}, a, b, c),   // parallel above the plane
      makeCase({0.25f, 0.25f, 1}, {0, 0, 1}, a, b, c),   // pointing away
      makeCase({0.25f, 0.25f, 1}, {0, 0, -1}, a, b, c, 0.0f, 0.5f), // beyond tmax
      makeCase({0.25f, 0.25f, 1}, {0, 0, -1}, a, b, c, 1.0f, 2.0f), // t == tmin excluded
      makeCase({0.25f, 0.25f, 1}, {0, 0, -1}, a, b, c, 0.0f, 1.0f), // t == tmax included
      makeCase({0.2f, 0.2f, 1}, {0.1f, 0.1f, -1}, a, b, c),         // oblique
      makeCase({2, 2, 1}, {0, 0, -1}, a, b, c),                     // outside
  };
  const bool expected[] = {true, true, true, true, true, false, false, false, false, false, true, true, false};
  auto gpu = runCases<IntersectCase, glm::vec4>(context(), kSpirv_intersect_test, cases);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    CpuResult cpu = cpuIntersect(cases[i]);
    EXPECT_EQ(cpu.hit, expected[i]) << "CPU, case " << i;
    expectSame(cases[i], cpu, gpu[i], i);
  }
  // The interior hit: t = 1, barycentrics of b and c are 0.25 each.
  EXPECT_FLOAT_EQ(gpu[0].y, 1.0f);
  EXPECT_FLOAT_EQ(gpu[0].z, 0.25f);
  EXPECT_FLOAT_EQ(gpu[0].w, 0.25f);
}

TEST_F(IntersectShader, SharedEdgeIsWatertight) {
  // Two triangles sharing the diagonal of the unit square; rays hit exactly on the diagonal and
  // at random points very close to it. Every ray must hit at least one of the two.
  const glm::vec3 p00(0, 0, 0), p10(1, 0, 0), p01(0, 1, 0), p11(1, 1, 0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), jitter(-1e-6f, 1e-6f);
  std::vector<IntersectCase> cases;
  for (int i = 0; i < 20000; ++i) {
    float s = u(rng);
    glm::vec3 onEdge(s + jitter(rng), 1.0f - s + jitter(rng), 0.0f);
    glm::vec3 o = onEdge + glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, 1.0f + u(rng));
    cases.push_back(makeCase(o, onEdge - o, p10, p11, p01)); // upper-right triangle
    cases.push_back(makeCase(o, onEdge - o, p00, p10, p01)); // lower-left triangle
  }
  auto gpu = runCases<IntersectCase, glm::vec4>(context(), kSpirv_intersect_test, cases);
  std::size_t gpuLeaks = 0, cpuLeaks = 0;
  for (std::size_t i = 0; i < cases.size(); i += 2) {
    gpuLeaks += gpu[i].x == 0.0f && gpu[i + 1].x == 0.0f;
    cpuLeaks += !cpuIntersect(cases[i]).hit && !cpuIntersect(cases[i + 1]).hit;
  }
  EXPECT_EQ(gpuLeaks, 0u);
  EXPECT_EQ(cpuLeaks, 0u);
}

TEST_F(IntersectShader, TinyAndNeedleTriangles) {
  std::vector<IntersectCase> cases = {
      // A triangle 1e-6 across at distance 1, hit in its middle.
      makeCase({0.3e-6f, 0.3e-6f, 1}, {0, 0, -1}, {0, 0, 0}, {1e-6f, 0, 0}, {0, 1e-6f, 0}),
      // A needle of aspect ratio 1e6.
      makeCase({0.5f, 0.25e-6f, 1}, {0, 0, -1}, {0, 0, 0}, {1, 0, 0}, {0, 1e-6f, 0}),
  };
  auto gpu = runCases<IntersectCase, glm::vec4>(context(), kSpirv_intersect_test, cases);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(gpu[i].x, 1.0f) << "case " << i;
    EXPECT_NEAR(gpu[i].y, 1.0f, 1e-6f) << "case " << i;
    expectSame(cases[i], cpuIntersect(cases[i]), gpu[i], i);
  }
}

struct BoxCase {
  gpu::GpuRay ray;
  glm::vec4 lo, hi;
};

TEST_F(IntersectShader, BoxSlabTestHandlesZeroDirectionComponents) {
  const glm::vec4 lo(0, 0, 0, 0), hi(1, 1, 1, 0);
  auto ray = [](glm::vec3 o, glm::vec3 d) { return gpu::GpuRay{glm::vec4(o, 0), glm::vec4(d, INFINITY)}; };
  std::vector<BoxCase> cases = {
      {ray({0.5f, 0.5f, -1}, {0, 0, 1}), lo, hi},  // axis-aligned through the middle
      {ray({0.0f, 0.5f, -1}, {0, 0, 1}), lo, hi},  // in the x = 0 face plane: touches
      {ray({1.0f, 1.0f, -1}, {0, 0, 1}), lo, hi},  // along an edge
      {ray({1.5f, 0.5f, -1}, {0, 0, 1}), lo, hi},  // parallel, outside
      {ray({0.5f, 0.5f, 2}, {0, 0, 1}), lo, hi},   // pointing away
      {ray({0.5f, 0.5f, 0.5f}, {1, 0, 0}), lo, hi}, // from inside
      {ray({0.5f, 0.5f, -1}, {0, 0, 1}), {0.5f, 0, 0, 0}, {0.5f, 1, 1, 0}}, // flat box, ray in its plane
  };
  const bool expected[] = {true, true, true, false, false, true, true};
  for (auto& c : cases) render::widenBox(c.lo, c.hi); // as the production packing does
  auto gpu = runCases<BoxCase, glm::vec4>(context(), kSpirv_box_test, cases);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    EXPECT_EQ(gpu[i].x != 0.0f, expected[i]) << "case " << i;
    EXPECT_FALSE(std::isnan(gpu[i].y) || std::isnan(gpu[i].z)) << "case " << i;
  }
}

} // namespace
} // namespace obscura::test
