// The production bsdf.glsl on lavapipe against its C++ twin (host/shading/bsdf.h): eval, pdf and
// sample agree on random inputs; a sample's weight is eval cos / pdf; sampleBsdf's directions follow
// bsdfPdf (chi-square), with the mass that falls below the horizon reported as "no sample".
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "bsdf_test.spv.h"
#include "gpu_test.h"
#include "shading/bsdf.h"
#include "shaders/shader_runner.h"

#include "chi_square.h"

namespace obscura::test {



namespace {

struct BsdfCase {
  glm::vec4 material; // rgb base colour, w = metallic
  glm::vec4 wo;       // xyz, w = roughness
  glm::vec4 wi;
  glm::vec4 u;
  glm::uvec4 mode; // x = mode, y = seed
};
static_assert(sizeof(BsdfCase) == 80);
constexpr std::uint32_t kModeEval = 0, kModeSample = 1;
constexpr std::size_t kOutPerCase = 16;
struct BsdfResult {
  std::array<glm::vec4, kOutPerCase> r;
};

class BsdfShader : public GpuTest {
public:
  std::vector<BsdfResult> run(const std::vector<BsdfCase>& cases) {
    return runCases<BsdfCase, BsdfResult>(context(), kSpirv_bsdf_test, cases);
  }
};

glm::vec3 randomDirection(std::mt19937& rng, bool upper) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  float z = upper ? u(rng) : 2.0f * u(rng) - 1.0f;
  float phi = 2.0f * shading::kPi * u(rng);
  float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// |gpu - cpu| <= tol * max(|cpu|, floor): relative, with an absolute floor for values near 0.
void expectClose(float gpu, float cpu, float tol, float floor, const char* what, std::size_t i) {
  EXPECT_LE(std::abs(gpu - cpu), tol * std::max(std::abs(cpu), floor)) << what << ", case " << i << ": gpu " << gpu
                                                                         << ", cpu " << cpu;
}
void expectClose(glm::vec3 gpu, glm::vec3 cpu, float tol, float floor, const char* what, std::size_t i) {
  for (int k = 0; k < 3; ++k) expectClose(gpu[k], cpu[k], tol, floor, what, i);
}

// Random materials of every kind (Lambertian, mirror, clamped-alpha, glossy dielectric, metal,
// in between), directions in and out of the upper hemisphere.
std::vector<BsdfCase> randomCases(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<BsdfCase> cases;
  for (std::size_t i = 0; i < count; ++i) {
    float metallic = std::array<float, 4>{0.0f, 1.0f, u(rng), 0.0f}[i % 4];
    float roughness = std::array<float, 6>{1.0f, 0.0f, 0.02f, 0.05f + 0.95f * u(rng), 0.3f, 0.7f}[(i / 4) % 6];
    glm::vec3 wo = randomDirection(rng, i % 17 != 0), wi = randomDirection(rng, i % 13 != 0);
    cases.push_back({glm::vec4(u(rng), u(rng), u(rng), metallic), glm::vec4(wo, roughness), glm::vec4(wi, 0.0f),
                     glm::vec4(u(rng), u(rng), u(rng), 0.0f), glm::uvec4(kModeEval, 0, 0, 0)});
  }
  return cases;
}

// GPU == CPU on 20,000 random inputs: 1e-4 relative (a fused multiply-add or a transcendental a
// few ulps apart on either side moves results by ~1e-6; the tolerance leaves room for the GGX peak,
// where D changes by 1e-4 over an ulp of cos(theta_h) when alpha is near its minimum).
TEST_F(BsdfShader, MatchesCpuTwin) {
  auto cases = randomCases(20000, 5);
  auto gpu = run(cases);
  constexpr float kTol = 1e-4f;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const BsdfCase& c = cases[i];
    const auto& g = gpu[i].r;
    glm::vec3 color(c.material), wo(c.wo), wi(c.wi), u3(c.u);
    float metallic = c.material.w, roughness = c.wo.w;
    expectClose(glm::vec3(g[0]), shading::evalBsdf(color, metallic, roughness, wo, wi), kTol, 1.0f, "evalBsdf", i);
    expectClose(g[0].w, shading::bsdfPdf(color, metallic, roughness, wo, wi), kTol, 1.0f, "bsdfPdf", i);
    glm::vec3 cpuWi;
    float cpuPdf = 0.0f;
    bool cpuDelta = false;
    glm::vec3 cpuWeight = shading::sampleBsdf(color, metallic, roughness, wo, u3, cpuWi, cpuPdf, cpuDelta);
    ASSERT_EQ(g[2].w != 0.0f, cpuDelta) << i;
    ASSERT_EQ(g[1].w > 0.0f, cpuPdf > 0.0f) << i;
    // Sampled directions agree to 1e-4; their pdfs are compared at the GPU's direction, because
    // next to a narrow GGX peak (alpha = kGgxMinAlpha) a rounding-level change of the direction
    // changes D by far more than 1e-4. The weight f cos / pdf has no such peak.
    if (cpuPdf > 0.0f) {
      glm::vec3 gpuWi(g[2]);
      expectClose(gpuWi, cpuWi, kTol, 1.0f, "sampleBsdf wi", i);
      expectClose(glm::vec3(g[1]), cpuWeight, kTol, 1.0f, "sampleBsdf weight", i);
      float cpuPdfThere = cpuDelta ? cpuPdf : shading::bsdfPdf(color, metallic, roughness, wo, gpuWi);
      expectClose(g[1].w, cpuPdfThere, kTol, 1.0f, "sampleBsdf pdf", i);
      expectClose(glm::vec3(g[3]), shading::evalBsdf(color, metallic, roughness, wo, gpuWi), kTol, 1.0f,
                  "evalBsdf at the sample", i);
    }
    expectClose(glm::vec3(g[7]), cpuWeight, kTol, 1.0f, "sampleBsdf (7 arguments) weight", i);
    float alpha = shading::ggxAlpha(roughness);
    expectClose(g[4].x, shading::ggxD(wi.z, alpha), kTol, 1.0f, "ggxD", i);
    expectClose(g[8].x, shading::ggxD(wo + wi, alpha), kTol, 1.0f, "ggxD (vector)", i);
    expectClose(g[4].y, shading::smithG1(wo.z, alpha), kTol, 1.0f, "smithG1", i);
    expectClose(g[4].z, shading::smithG2(wo.z, wi.z, alpha), kTol, 1.0f, "smithG2", i);
    expectClose(g[4].w, shading::ggxReflectionPdf(wo, wi, alpha), kTol, 1.0f, "ggxReflectionPdf", i);
    if (wo.z > 0.0f) {
      glm::vec3 h = shading::sampleGgxVisibleNormal(wo, alpha, glm::vec2(u3.y, u3.z)), gpuH(g[5]);
      expectClose(gpuH, h, kTol, 1.0f, "sampleGgxVisibleNormal", i);
      expectClose(g[5].w, shading::ggxVisibleNormalPdf(wo, gpuH, alpha), kTol, 1.0f, "ggxVisibleNormalPdf", i);
    }
    EXPECT_EQ(g[6].x != 0.0f, shading::isGlossy(metallic, roughness)) << i;
    EXPECT_EQ(g[6].y != 0.0f, shading::isMirror(roughness)) << i;
    expectClose(g[6].z, shading::specularProbability(color, metallic, wo.z), kTol, 1.0f, "specularProbability", i);
    EXPECT_EQ(g[6].w, alpha) << i;
    if (HasFailure()) return;
  }
}

// For every GPU sample: weight == evalBsdf(wi) wi.z / bsdfPdf(wi) (both evaluated on the GPU for
// the returned direction); a mirror sample is the reflection of wo with weight F(wo.z) / p.
TEST_F(BsdfShader, SampleWeightIsEvalCosOverPdf) {
  auto cases = randomCases(20000, 9);
  auto gpu = run(cases);
  std::size_t checked = 0, deltas = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const BsdfCase& c = cases[i];
    const auto& g = gpu[i].r;
    glm::vec3 wo(c.wo), wi(g[2]), weight(g[1]);
    float pdf = g[1].w;
    if (pdf == 0.0f) {
      EXPECT_EQ(weight, glm::vec3(0.0f)) << i;
      continue;
    }
    EXPECT_NEAR(glm::length(wi), 1.0f, 1e-5f) << i;
    EXPECT_GT(wi.z, 0.0f) << i;
    if (g[2].w != 0.0f) { // delta
      ++deltas;
      EXPECT_TRUE(shading::isMirror(c.wo.w)) << i;
      EXPECT_NEAR(glm::length(wi - glm::vec3(-wo.x, -wo.y, wo.z)), 0.0f, 1e-6f) << i;
      glm::vec3 f0 = glm::mix(glm::vec3(shading::kDielectricF0), glm::vec3(c.material), c.material.w);
      expectClose(weight, shading::fresnelSchlick(f0, wo.z) / pdf, 1e-5f, 1e-3f, "mirror weight", i);
      continue;
    }
    ++checked;
    EXPECT_EQ(g[3].w, pdf) << i; // sampleBsdf's pdf is bsdfPdf of its direction
    expectClose(weight, glm::vec3(g[3]) * wi.z / g[3].w, 1e-5f, 1e-3f, "weight", i);
    if (HasFailure()) return;
  }
  EXPECT_GT(checked, cases.size() / 2);
  EXPECT_GT(deltas, 100u);
}

// 10^6 GPU samples of a glossy material for wo at 50 degrees, binned in (cos(theta_i), phi): 40 x 80 cells of equal solid angle. Expected counts integrate the
// CPU bsdfPdf over each cell (8 x 8 midpoints); one more cell holds the samples that fell below the
// horizon, expected N (1 - integral of bsdfPdf).
ChiSquare glossyChiSquare(BsdfShader& test, glm::vec3 color, float metallic, float roughness, double& lost,
                          double& expectedLost) {
  const float theta = 50.0f * shading::kPi / 180.0f;
  const glm::vec3 wo(std::sin(theta), 0.0f, std::cos(theta));
  const std::size_t caseCount = 1'000'000 / kOutPerCase;
  std::vector<BsdfCase> cases(caseCount, BsdfCase{glm::vec4(color, metallic), glm::vec4(wo, roughness), {}, {},
                                                  glm::uvec4(kModeSample, 777, 0, 0)});
  auto gpu = test.run(cases);

  constexpr int kZ = 40, kPhi = 80, kSub = 8;
  std::vector<double> observed(kZ * kPhi + 1, 0.0), expected(kZ * kPhi + 1, 0.0);
  const double n = double(caseCount * kOutPerCase);
  for (const auto& res : gpu)
    for (const auto& s : res.r) {
      if (s.w == 0.0f) {
        observed[kZ * kPhi] += 1.0;
        continue;
      }
      EXPECT_GT(s.w, 0.0f); // no delta for this material
      double phi = std::atan2(double(s.y), double(s.x));
      if (phi < 0.0) phi += 2.0 * M_PI;
      int iz = std::min(int(double(s.z) * kZ), kZ - 1);
      int ip = std::min(int(phi / (2.0 * M_PI) * kPhi), kPhi - 1);
      observed[iz * kPhi + ip] += 1.0;
    }
  double total = 0.0;
  for (int iz = 0; iz < kZ; ++iz)
    for (int ip = 0; ip < kPhi; ++ip) {
      double sum = 0.0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) {
          double z = (iz + (a + 0.5) / kSub) / kZ, phi = 2.0 * M_PI * (ip + (b + 0.5) / kSub) / kPhi;
          double s = std::sqrt(std::max(0.0, 1.0 - z * z));
          glm::vec3 wi(float(s * std::cos(phi)), float(s * std::sin(phi)), float(z));
          sum += shading::bsdfPdf(color, metallic, roughness, wo, wi);
        }
      double p = sum / (kSub * kSub) * (1.0 / kZ) * (2.0 * M_PI / kPhi); // dw = dz dphi
      expected[iz * kPhi + ip] = n * p;
      total += p;
    }
  expected[kZ * kPhi] = n * std::max(0.0, 1.0 - total);
  lost = observed[kZ * kPhi];
  expectedLost = expected[kZ * kPhi];
  return chiSquareTest(observed, expected);
}

// Roughness 0.5: a dielectric (both lobes, the specular one picked with ~7%) and a metal (GGX only).
TEST_F(BsdfShader, GlossySampleChiSquare) {
  struct Material {
    const char* name;
    glm::vec3 color;
    float metallic, roughness;
  };
  for (const Material& m : {Material{"dielectric", glm::vec3(0.8f, 0.6f, 0.4f), 0.0f, 0.5f},
                            Material{"metal", glm::vec3(0.9f, 0.7f, 0.5f), 1.0f, 0.5f}}) {
    double lost = 0.0, expectedLost = 0.0;
    ChiSquare chi = glossyChiSquare(*this, m.color, m.metallic, m.roughness, lost, expectedLost);
    EXPECT_TRUE(chi.passed()) << m.name << ": chi2 = " << chi.value << ", dof " << chi.dof << ", threshold "
                              << chi.threshold;
    std::printf("[ chi2     ] sampleBsdf vs bsdfPdf (%s, roughness 0.5, 50 deg): %.1f (dof %d, threshold %.1f at "
                "p = 1e-4); below the horizon %.0f of 1e6 (expected %.0f)\n",
                m.name, chi.value, chi.dof, chi.threshold, lost, expectedLost);
  }
}

// A mirror dielectric: the delta is chosen with probability specularProbability(wo.z), within 5
// binomial standard deviations over 10^5 samples.
TEST_F(BsdfShader, MirrorDeltaFrequencyIsItsProbability) {
  const glm::vec3 color(0.5f), wo = glm::normalize(glm::vec3(0.8f, 0.1f, 0.3f));
  std::vector<BsdfCase> cases(100'000 / kOutPerCase, BsdfCase{glm::vec4(color, 0.0f), glm::vec4(wo, 0.0f), {}, {},
                                                              glm::uvec4(kModeSample, 99, 0, 0)});
  auto gpu = run(cases);
  double deltas = 0.0, n = double(cases.size() * kOutPerCase);
  for (const auto& res : gpu)
    for (const auto& s : res.r) deltas += s.w < 0.0f;
  double p = shading::specularProbability(color, 0.0f, wo.z);
  EXPECT_NEAR(deltas / n, p, 5.0 * std::sqrt(p * (1.0 - p) / n));
}

} // namespace
} // namespace obscura::test
