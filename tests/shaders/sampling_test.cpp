// The production sampling.glsl on lavapipe: its warps follow their pdfs (chi-square), systematic
// sampling puts one ray in each cell [RTO §4.2, SPEC §1.4], the warps invert, and the GPU agrees
// with the C++ twins (host/shading/bsdf.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "gpu_test.h"
#include "shading/bsdf.h"
#include "sampling_test.spv.h"
#include "chi_square.h"
#include "shaders/shader_runner.h"

namespace obscura::test {

namespace {
constexpr double kPi = 3.14159265358979323846;

struct SamplingCase {
  glm::uvec4 mode; // x = mode, y = n, z = seed, w = ray index
  glm::vec4 a, b, c;
};
static_assert(sizeof(SamplingCase) == 64);
constexpr std::uint32_t kModeCosine = 0, kModeSystematic = 1, kModeGrid = 2, kModeTriangle = 3, kModeWarps = 4,
                        kModeSpherical = 5;
constexpr std::size_t kOutPerCase = 64;
struct SamplingResult {
  std::array<glm::vec4, kOutPerCase> v;
};

class SamplingShader : public GpuTest {
protected:
  std::vector<SamplingResult> run(const std::vector<SamplingCase>& cases) {
    return runCases<SamplingCase, SamplingResult>(context(), kSpirv_sampling_test, cases);
  }
  // `count` cases of one mode, each with its own seed.
  std::vector<SamplingResult> runMode(std::uint32_t mode, std::uint32_t n, std::size_t count,
                                      glm::vec4 a = {}, glm::vec4 b = {}, glm::vec4 c = {}) {
    std::vector<SamplingCase> cases(count);
    for (std::size_t i = 0; i < count; ++i) cases[i] = {{mode, n, 12345u, 0u}, a, b, c};
    return run(cases);
  }
};

// Equal-probability bins of the cosine-weighted hemisphere: sin^2(theta) = x^2 + y^2 and phi are
// both uniform under pdf cos(theta) / pi.
constexpr int kBinsS = 20, kBinsPhi = 40;
int cosineBin(glm::vec3 w) {
  double s = std::clamp(double(w.x) * w.x + double(w.y) * w.y, 0.0, 1.0);
  double phi = std::atan2(double(w.y), double(w.x));
  if (phi < 0.0) phi += 2.0 * M_PI;
  int is = std::min(int(s * kBinsS), kBinsS - 1);
  int ip = std::min(int(phi / (2.0 * M_PI) * kBinsPhi), kBinsPhi - 1);
  return is * kBinsPhi + ip;
}

ChiSquare cosineChiSquare(const std::vector<SamplingResult>& results, std::size_t& count) {
  std::vector<double> observed(kBinsS * kBinsPhi, 0.0);
  count = 0;
  for (const auto& r : results)
    for (const auto& v : r.v) {
      if (v.w == 0.0f) continue;
      EXPECT_GE(v.z, 0.0f);
      EXPECT_NEAR(glm::length(glm::vec3(v)), 1.0f, 1e-5f);
      observed[cosineBin(glm::vec3(v))] += 1.0;
      ++count;
    }
  std::vector<double> expected(observed.size(), double(count) / double(observed.size()));
  return chiSquareTest(observed, expected);
}

TEST_F(SamplingShader, SystematicGridFactorisations) {
  const std::uint32_t maxN = 100;
  std::vector<SamplingCase> cases;
  for (std::uint32_t n = 1; n <= maxN; ++n) cases.push_back({{kModeGrid, n, 0u, 0u}, {}, {}, {}});
  auto gpu = run(cases);
  for (std::uint32_t n = 1; n <= maxN; ++n) {
    std::uint32_t best = 1; // the largest divisor <= sqrt(n), by brute force
    for (std::uint32_t d = 1; d * d <= n; ++d)
      if (n % d == 0) best = d;
    glm::uvec2 cpu = shading::systematicGrid(n);
    EXPECT_EQ(cpu, glm::uvec2(n / best, best)) << "n = " << n;
    EXPECT_EQ(glm::uvec2(gpu[n - 1].v[0]), cpu) << "n = " << n;
  }
  EXPECT_EQ(shading::systematicGrid(5), glm::uvec2(5, 1));
  EXPECT_EQ(shading::systematicGrid(4), glm::uvec2(2, 2));
  EXPECT_EQ(shading::systematicGrid(40), glm::uvec2(8, 5)); // the paper's 40 rays per pixel
  EXPECT_EQ(shading::systematicGrid(1), glm::uvec2(1, 1));
  EXPECT_EQ(shading::systematicGrid(97), glm::uvec2(97, 1));
  EXPECT_EQ(shading::systematicGrid(0), glm::uvec2(0, 0));
}

// 10^6 random cosine samples (u from rng.glsl) against cos(theta) / pi.
TEST_F(SamplingShader, CosineHemisphereChiSquare) {
  std::size_t count = 0;
  ChiSquare chi = cosineChiSquare(runMode(kModeCosine, 0, 1'000'000 / kOutPerCase), count);
  EXPECT_EQ(count, 1'000'000 / kOutPerCase * kOutPerCase);
  EXPECT_TRUE(chi.passed()) << "chi2 = " << chi.value << ", dof " << chi.dof << ", threshold " << chi.threshold;
  std::printf("[ chi2     ] cosine hemisphere: %.1f (dof %d, threshold %.1f at p = 1e-4)\n", chi.value, chi.dof,
              chi.threshold);
}

// Systematic sets, each hit with its own random offset, pooled: every ray is cosine-distributed.
// (Stratification makes the counts less variable than multinomial, so the test is conservative.)
TEST_F(SamplingShader, SystematicChiSquare) {
  for (std::uint32_t n : {5u, 16u}) {
    std::size_t count = 0;
    std::size_t cases = 1'000'000 / ((kOutPerCase / n) * n) + 1;
    ChiSquare chi = cosineChiSquare(runMode(kModeSystematic, n, cases), count);
    EXPECT_GE(count, 1'000'000u);
    EXPECT_TRUE(chi.passed()) << "n = " << n << ": chi2 = " << chi.value << ", dof " << chi.dof << ", threshold "
                              << chi.threshold;
    std::printf("[ chi2     ] systematic n = %u: %.1f (dof %d, threshold %.1f at p = 1e-4)\n", n, chi.value, chi.dof,
                chi.threshold);
  }
}

// Ray r of every hit lies in cell (r % nPhi, r / nPhi): phi in [2 pi i / nPhi, 2 pi (i + 1) / nPhi),
// sin^2(theta) in [j / nTheta, (j + 1) / nTheta). So each of the nPhi x nTheta cells gets exactly
// one ray. The tolerance (1e-4 of a cell) only absorbs float rounding at the cell borders.
TEST_F(SamplingShader, SystematicPutsOneRayInEachCell) {
  for (std::uint32_t n : {1u, 4u, 5u, 7u, 16u, 40u, 64u}) {
    glm::uvec2 grid = shading::systematicGrid(n);
    auto results = runMode(kModeSystematic, n, 2000);
    std::size_t hits = 0, outside = 0;
    for (const auto& res : results) {
      for (std::size_t h = 0; h < kOutPerCase / n; ++h, ++hits) {
        std::vector<int> perCell(n, 0);
        for (std::uint32_t r = 0; r < n; ++r) {
          glm::vec3 w(res.v[h * n + r]);
          double phi = std::atan2(double(w.y), double(w.x));
          if (phi < 0.0) phi += 2.0 * M_PI;
          double x = phi / (2.0 * M_PI) * grid.x;                            // in [i, i + 1)
          double y = (double(w.x) * w.x + double(w.y) * w.y) * grid.y;        // in [j, j + 1)
          double i = r % grid.x, j = r / grid.x;
          constexpr double kTol = 1e-4;
          double dx = x - i;
          if (dx < -0.5 * grid.x) dx += grid.x; // phi just below 2 pi belongs to the last column
          bool inCell = dx > -kTol && dx < 1.0 + kTol && y > j - kTol && y < j + 1.0 + kTol;
          outside += !inCell;
          int cx = std::clamp(int(std::floor(x)), 0, int(grid.x) - 1);
          int cy = std::clamp(int(std::floor(y)), 0, int(grid.y) - 1);
          if (inCell) ++perCell[std::size_t(cy) * grid.x + cx];
        }
        // Away from borders the rays fill every cell once.
        std::size_t ones = std::count(perCell.begin(), perCell.end(), 1);
        EXPECT_GE(ones + 2, std::size_t(n)) << "n = " << n << ", hit " << hits;
      }
    }
    EXPECT_EQ(outside, 0u) << "n = " << n << " (" << grid.x << " x " << grid.y << ")";
    EXPECT_GE(hits, 2000u);
  }
}

// The triangle split by a k x k grid of its barycentrics into k^2 congruent sub-triangles: the
// index of the one holding barycentrics (b1, b2) of vertices 1 and 2. Row j holds 2 (k - j) - 1
// sub-triangles, "up" ones at even positions and the "down" ones between them.
int subTriangleCell(double b1, double b2, int k) {
  double x = std::clamp(b1 * k, 0.0, k - 1e-9), y = std::clamp(b2 * k, 0.0, k - 1e-9);
  int i = int(x), j = int(y);
  bool up = (x - i) + (y - j) < 1.0;
  int row = 0;
  for (int jj = 0; jj < j; ++jj) row += 2 * (k - jj) - 1;
  return std::min(row + 2 * i + (up ? 0 : 1), k * k - 1);
}

// The corners of sub-triangle `cell` (subTriangleCell's numbering) of triangle (v0, v1, v2).
std::array<glm::dvec3, 3> subTriangle(int cell, int k, glm::dvec3 v0, glm::dvec3 v1, glm::dvec3 v2) {
  auto at = [&](int i, int j) { return v0 + (double(i) / k) * (v1 - v0) + (double(j) / k) * (v2 - v0); };
  int j = 0, row = 0;
  while (cell >= row + 2 * (k - j) - 1) row += 2 * (k - j++) - 1;
  int offset = cell - row, i = offset / 2;
  if (offset % 2 == 0) return {at(i, j), at(i + 1, j), at(i, j + 1)};
  return {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
}

// Solid angle of a triangle seen from the origin, in double (Van Oosterom & Strackee 1983).
double solidAngle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  a = glm::normalize(a), b = glm::normalize(b), c = glm::normalize(c);
  return 2.0 * std::atan2(std::abs(glm::dot(a, glm::cross(b, c))), 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a));
}

// 10^6 points on a skewed triangle in 3-D, binned in its 8^2 congruent sub-triangles (equal areas).
TEST_F(SamplingShader, UniformTriangleChiSquare) {
  const glm::vec3 v0(0.3f, -1.0f, 2.0f), v1(4.0f, 0.5f, 1.0f), v2(-1.0f, 2.0f, -0.5f);
  auto results = runMode(kModeTriangle, 0, 1'000'000 / kOutPerCase, glm::vec4(v0, 0), glm::vec4(v1, 0), glm::vec4(v2, 0));
  const int k = 8;
  std::vector<double> observed(k * k, 0.0);
  const glm::dvec3 e1 = glm::dvec3(v1 - v0), e2 = glm::dvec3(v2 - v0);
  const double a11 = glm::dot(e1, e1), a12 = glm::dot(e1, e2), a22 = glm::dot(e2, e2), det = a11 * a22 - a12 * a12;
  const double area = 0.5 * glm::length(glm::cross(e1, e2));
  std::size_t count = 0;
  double maxOffPlane = 0.0, minBary = 1.0;
  for (const auto& r : results)
    for (const auto& v : r.v) {
      EXPECT_NEAR(v.w, area, 1e-5 * area);
      glm::dvec3 d = glm::dvec3(glm::vec3(v)) - glm::dvec3(v0);
      double r1 = glm::dot(d, e1), r2 = glm::dot(d, e2);
      double b1 = (a22 * r1 - a12 * r2) / det, b2 = (a11 * r2 - a12 * r1) / det; // barycentrics of v1, v2
      maxOffPlane = std::max(maxOffPlane, glm::length(d - b1 * e1 - b2 * e2));
      minBary = std::min({minBary, b1, b2, 1.0 - b1 - b2});
      observed[subTriangleCell(b1, b2, k)] += 1.0;
      ++count;
    }
  EXPECT_LT(maxOffPlane, 1e-5);
  EXPECT_GT(minBary, -1e-6);
  EXPECT_NEAR(shading::triangleArea(v0, v1, v2), area, 1e-5 * area);
  std::vector<double> expected(observed.size(), double(count) / observed.size());
  ChiSquare chi = chiSquareTest(observed, expected);
  EXPECT_TRUE(chi.passed()) << "chi2 = " << chi.value << ", dof " << chi.dof << ", threshold " << chi.threshold;
  std::printf("[ chi2     ] uniform triangle: %.1f (dof %d, threshold %.1f at p = 1e-4)\n", chi.value, chi.dof,
              chi.threshold);
}

// Directions uniform in solid angle over spherical triangles (Arvo 1995) [SPEC §1.3]: 640,000
// directions per triangle, binned by where they cross the flat triangle into its 6^2 sub-triangles,
// each expected in proportion to its own solid angle (double precision); a triangle seen head on,
// one covering most of a hemisphere, and a sliver seen at a grazing angle (the adjacent facets of
// a tessellated light). The solid angle matches the analytic octant's pi / 2.
TEST_F(SamplingShader, SphericalTriangleChiSquare) {
  struct Case {
    const char* name;
    glm::dvec3 v0, v1, v2; // seen from the origin
  };
  const Case cases[] = {
      {"octant", {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
      {"near hemisphere", {4, -3, 0.2}, {-4, -3, 0.2}, {0, 5, 0.2}},
      {"grazing sliver", {1, 1, 0.02}, {3, 1, 0.02}, {2, 3, 0.02}},
  };
  const int k = 6;
  for (const Case& c : cases) {
    glm::vec4 a(glm::normalize(glm::vec3(c.v0)), 0), b(glm::normalize(glm::vec3(c.v1)), 0), cc(glm::normalize(glm::vec3(c.v2)), 0);
    auto results = runMode(kModeSpherical, 0, 640'000 / kOutPerCase, a, b, cc);
    const double total = solidAngle(c.v0, c.v1, c.v2);
    const glm::dvec3 n = glm::cross(c.v1 - c.v0, c.v2 - c.v0);
    const glm::dvec3 e1 = c.v1 - c.v0, e2 = c.v2 - c.v0;
    const double a11 = glm::dot(e1, e1), a12 = glm::dot(e1, e2), a22 = glm::dot(e2, e2), det = a11 * a22 - a12 * a12;
    std::vector<double> observed(k * k, 0.0), expected(k * k, 0.0);
    std::size_t count = 0, outside = 0;
    for (const auto& r : results)
      for (const auto& v : r.v) {
        EXPECT_NEAR(v.w, total, 1e-4 * total) << c.name; // float inputs; the sliver cancels most
        glm::dvec3 w = glm::dvec3(glm::vec3(v));
        EXPECT_NEAR(glm::length(w), 1.0, 1e-5) << c.name;
        glm::dvec3 y = w * (glm::dot(c.v0, n) / glm::dot(w, n)); // where w crosses the triangle's plane
        glm::dvec3 d = y - c.v0;
        double r1 = glm::dot(d, e1), r2 = glm::dot(d, e2);
        double b1 = (a22 * r1 - a12 * r2) / det, b2 = (a11 * r2 - a12 * r1) / det;
        if (std::min({b1, b2, 1.0 - b1 - b2}) < -1e-4) ++outside;
        observed[subTriangleCell(b1, b2, k)] += 1.0;
        ++count;
      }
    double sum = 0.0;
    for (int cell = 0; cell < k * k; ++cell) {
      auto t = subTriangle(cell, k, c.v0, c.v1, c.v2);
      expected[cell] = solidAngle(t[0], t[1], t[2]);
      sum += expected[cell];
    }
    EXPECT_NEAR(sum, total, 1e-9 * total) << c.name << ": the sub-triangles must tile the triangle";
    for (double& e : expected) e *= double(count) / sum;
    EXPECT_LE(outside, count / 100000) << c.name << ": directions must lie in the triangle";
    ChiSquare chi = chiSquareTest(observed, expected);
    EXPECT_TRUE(chi.passed()) << c.name << ": chi2 = " << chi.value << ", dof " << chi.dof << ", threshold " << chi.threshold;
    std::printf("[ chi2     ] spherical triangle, %s (%.4g sr): %.1f (dof %d, threshold %.1f at p = 1e-4)\n", c.name,
                total, chi.value, chi.dof, chi.threshold);
  }
  EXPECT_NEAR(shading::sphericalTriangleArea({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), kPi / 2.0, 1e-6);
}

// GPU == CPU twin for Arvo's warp on random triangles around the origin.
TEST_F(SamplingShader, SphericalTriangleWarpMatchesCpu) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::normal_distribution<float> normal;
  std::vector<SamplingCase> cases;
  while (cases.size() < 4000) {
    glm::vec3 v[3];
    for (auto& x : v) x = glm::normalize(glm::vec3(normal(rng), normal(rng), normal(rng)));
    float area = shading::sphericalTriangleArea(v[0], v[1], v[2]);
    if (area < 3e-4f || area > 6.22f) continue; // the range lights.glsl samples this way
    cases.push_back({{kModeSpherical, 1u, 0u, 0u}, glm::vec4(v[0], uni(rng)), glm::vec4(v[1], uni(rng)), glm::vec4(v[2], 0)});
  }
  auto gpu = run(cases);
  std::vector<double> differences;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    glm::vec3 w = shading::sampleSphericalTriangle({c.a.w, c.b.w}, glm::vec3(c.a), glm::vec3(c.b), glm::vec3(c.c));
    EXPECT_NEAR(gpu[i].v[0].w, shading::sphericalTriangleArea(glm::vec3(c.a), glm::vec3(c.b), glm::vec3(c.c)),
                5e-5f * gpu[i].v[0].w + 1e-6f) << i; // lavapipe's atan: ~2e-5 relative
    differences.push_back(glm::length(glm::vec3(gpu[i].v[0]) - w));
  }
  // lavapipe's atan, sin and cos are not libm's. Most warps agree to float precision; for a tiny
  // u.x (a sliver sub-triangle at vertex a) Arvo's q is ill-conditioned in float on both sides,
  // and the two land up to a few milliradians apart, still inside the triangle (the chi-square
  // test above checks the distribution).
  std::sort(differences.begin(), differences.end());
  const double median = differences[differences.size() / 2], p99 = differences[differences.size() * 99 / 100];
  EXPECT_LT(median, 1e-5);
  EXPECT_LT(p99, 1e-3);
  EXPECT_LT(differences.back(), 2e-2);
  std::printf("[ twin     ] spherical triangle warp, GPU vs CPU: median %.2g, 99%% %.2g, largest %.2g\n", median, p99,
              differences.back());
}

// GPU == CPU twin for the deterministic warps; invertCosineHemisphereSample undoes
// sampleCosineHemisphere; orthonormalBasis is orthonormal and right-handed.
TEST_F(SamplingShader, WarpsInvertAndMatchCpu) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<SamplingCase> cases;
  std::vector<glm::vec3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, glm::normalize(glm::vec3(1e-4f, 0, -1))};
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 n = i < int(normals.size())
                      ? normals[i]
                      : glm::normalize(glm::vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f) + glm::vec3(1e-6f));
    glm::vec4 a(uni(rng), uni(rng), uni(rng), uni(rng));
    if (i == 0) a = glm::vec4(0.0f, 0.0f, 0.999f, 0.999f);
    if (i == 1) a = glm::vec4(shading::kOneMinusEpsilon, shading::kOneMinusEpsilon, 0.0f, 0.0f);
    std::uint32_t sysN = 1 + i % 40;
    cases.push_back({{kModeWarps, sysN, 0u, std::uint32_t(i) % sysN}, a, glm::vec4(n, 0),
                     glm::vec4(shading::sampleCosineHemisphere({uni(rng), uni(rng)}), 0)});
  }
  auto gpu = run(cases);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    const auto& g = gpu[i].v;
    glm::vec2 u(c.a.x, c.a.y);
    glm::vec3 w = shading::sampleCosineHemisphere(u);
    ASSERT_NEAR(glm::length(glm::vec3(g[0]) - w), 0.0f, 2e-6f) << i;
    ASSERT_NEAR(g[0].w, shading::cosineHemispherePdf(w.z), 2e-6f) << i;
    EXPECT_NEAR(glm::length(w), 1.0f, 1e-6f);
    // Round trip, on both sides; u.x is periodic, and undefined at the pole.
    for (glm::vec2 back : {shading::invertCosineHemisphereSample(w), glm::vec2(g[1])}) {
      EXPECT_NEAR(back.y, std::min(u.y, shading::kOneMinusEpsilon), 2e-6f) << i;
      float du = std::abs(back.x - u.x);
      if (u.y > 1e-6f) {
        EXPECT_LT(std::min(du, 1.0f - du), 2e-5f) << i << " u = " << u.x << ", " << u.y;
      }
    }
    glm::vec3 sys = shading::sampleSystematic(c.mode.w, shading::systematicGrid(c.mode.y), glm::vec2(c.a.z, c.a.w));
    ASSERT_NEAR(glm::length(glm::vec3(g[2]) - sys), 0.0f, 2e-6f) << i;
    glm::vec3 n(c.b), t, b;
    shading::orthonormalBasis(n, t, b);
    ASSERT_NEAR(glm::length(glm::vec3(g[3]) - t), 0.0f, 1e-6f) << i;
    ASSERT_NEAR(glm::length(glm::vec3(g[4]) - b), 0.0f, 1e-6f) << i;
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(b), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(t, b), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(t, n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(b, n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(glm::cross(t, b) - n), 0.0f, 1e-5f) << i; // right-handed
    glm::vec3 world = shading::toWorld(glm::vec3(c.c), t, b, n);
    EXPECT_NEAR(glm::dot(world, n), c.c.z, 1e-5f); // local z is the normal
    ASSERT_NEAR(glm::length(glm::vec3(g[5]) - world), 0.0f, 2e-6f) << i;
    if (HasFailure()) return;
  }
  // The extremes: u = 0 is the pole, u.y -> 1 the horizon (cos > 0 still).
  EXPECT_EQ(shading::sampleCosineHemisphere({0, 0}), glm::vec3(0, 0, 1));
  EXPECT_GT(shading::sampleCosineHemisphere({0.3f, 1.0f}).z, 0.0f);
}

} // namespace
} // namespace obscura::test
