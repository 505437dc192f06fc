// The light tree (render/scene_data/light_tree.h) and its selection (shaders/lib/lights.glsl beyond
// kMaxSpatialLights lights, twinned in render/scene_data/light_selection.h):
// - the tree holds every light with power in one leaf whose trail leads to it, each node bounds
//   its children (sphere, cone, power) and no leaf is deeper than the 32 trail bits;
// - at any point the selection pdfs of all lights and the share of descents that end at no light
//   (a node whose children cannot light the point) sum to 1, and every light that can light the
//   point (importance > 0) has a pdf > 0: the estimator stays unbiased;
// - the descent picks each light as often as its pdf says (chi-square), on the CPU and the GPU;
// - the GPU's choices and pdfs are the C++ twin's;
// - a floor under 150 point lights (dim ones near, bright ones far) renders to the analytic
//   irradiance with the tree and with selection by power, the tree with a fraction of the noise.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "chi_square.h"
#include "gpu/buffer.h"
#include "gpu/kernel.h"
#include "gpu_test.h"
#include "light_tree_test.spv.h"
#include "render/obscurance_renderer.h"
#include "render/one_shot.h"
#include "render/scene_data/light_selection.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/light_tree.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

using Tree = std::vector<gpu::GpuLightNode>;

// 40 area lights (quads of every orientation, some double-sided), 70 point lights, 30 spots and
// two suns over a 20 m box: more than kMaxSpatialLights, so the GPU descends the tree.
scene::Scene mixedLights() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  auto in = [&](float lo, float hi) { return lo + (hi - lo) * uni(rng); };
  auto direction = [&] {
    glm::vec3 d(in(-1, 1), in(-1, 1), in(-1, 1));
    return glm::length(d) > 1e-3f ? glm::normalize(d) : glm::vec3(0, -1, 0);
  };
  SceneBuilder b;
  auto floor = b.lambertian(glm::vec3(0.5f));
  b.quad({-10, 0, -10}, {0, 0, 20}, {20, 0, 0}, floor);
  for (int i = 0; i < 40; ++i) {
    auto emitter = b.lambertian(glm::vec3(0.0f), glm::vec3(in(0.1f, 5.0f)), i % 5 == 0);
    glm::vec3 u = direction() * in(0.05f, 1.0f), v = glm::normalize(glm::cross(u, direction())) * in(0.05f, 1.0f);
    b.quad({in(-10, 10), in(0.5f, 8), in(-10, 10)}, u, v, emitter, "quad" + std::to_string(i));
  }
  for (int i = 0; i < 70; ++i)
    b.pointLight({in(-10, 10), in(0.2f, 8), in(-10, 10)}, glm::vec3(1.0f), std::exp(in(-2, 6)), "point" + std::to_string(i));
  b.directionalLight({0.3f, -1.0f, 0.2f}, glm::vec3(1.0f), 2.0f);
  b.directionalLight({-0.5f, -0.4f, 0.1f}, glm::vec3(1.0f), 0.5f);
  scene::Scene s = b.build();
  for (int i = 0; i < 30; ++i) {
    scene::PunctualLight spot;
    spot.name = "spot" + std::to_string(i);
    spot.type = scene::PunctualType::Spot;
    spot.position = {in(-10, 10), in(1, 8), in(-10, 10)};
    spot.direction = direction();
    spot.intensity = std::exp(in(-1, 5));
    spot.innerConeAngle = in(0.0f, 0.3f);
    spot.outerConeAngle = spot.innerConeAngle + in(0.05f, 1.2f);
    s.punctualLights.push_back(spot);
  }
  return s;
}

struct Point {
  glm::vec3 p, n;
};

// Shading points in and around the lights' box, with normals of every direction.
std::vector<Point> randomPoints(std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  std::vector<Point> points;
  while (points.size() < count) {
    glm::vec3 n(uni(rng), uni(rng), uni(rng));
    if (glm::length(n) < 0.1f || glm::length(n) > 1.0f) continue;
    points.push_back({glm::vec3(12.0f * uni(rng), 4.5f + 5.0f * uni(rng), 12.0f * uni(rng)), glm::normalize(n)});
  }
  return points;
}

float cosOfAngleBetween(glm::vec3 a, glm::vec3 b) { return std::clamp(glm::dot(a, b), -1.0f, 1.0f); }

TEST(LightTree, EveryLightWithPowerIsOneLeafWhoseTrailLeadsToItAndNodesBoundTheirChildren) {
  const scene::Scene s = mixedLights();
  const render::LightSet set = render::buildLightSet(s);
  ASSERT_GT(set.size(), gpu::kMaxSpatialLights);
  const Tree tree = render::buildLightTree(set.lights);
  const glm::uvec4 header = tree[0].refs;
  ASSERT_NE(header.x, gpu::kInvalidIndex);
  EXPECT_EQ(header.y, 2u) << "the two suns are listed apart";
  EXPECT_EQ(header.z, set.size());
  EXPECT_LE(header.w, gpu::kLightTreeMaxDepth);
  // Walk every node from the root: children inside their parent, power summed, leaves met once.
  std::vector<int> seen(set.size(), 0);
  std::vector<std::uint32_t> stack{header.x};
  std::size_t internal = 0;
  while (!stack.empty()) {
    const std::uint32_t row = stack.back();
    stack.pop_back();
    const auto& node = tree[row];
    if (node.refs.y == gpu::kInvalidIndex) {
      ASSERT_LT(node.refs.x, set.size());
      EXPECT_EQ(row, 1u + node.refs.x) << "light i's leaf is row 1 + i";
      ++seen[node.refs.x];
      continue;
    }
    ++internal;
    double childPower = 0.0;
    for (std::uint32_t child : {node.refs.x, node.refs.y}) {
      childPower += tree[child].emission.x;
      stack.push_back(child);
    }
    EXPECT_NEAR(node.emission.x, childPower, 1e-5 * childPower) << row;
  }
  std::size_t bounded = 0;
  for (std::size_t i = 0; i < set.size(); ++i) {
    const bool inTree = !render::isUnboundedLight(set.lights[i].info.x) && set.lights[i].params.y > 0.0f;
    bounded += inTree;
    EXPECT_EQ(seen[i], inTree ? 1 : 0) << set.names[i];
    if (!inTree) {
      EXPECT_EQ(tree[1 + i].refs.w, gpu::kInvalidIndex) << set.names[i];
      continue;
    }
    // The trail leads from the root to the light's own leaf.
    const glm::uvec4 leaf = tree[1 + i].refs;
    ASSERT_LE(leaf.w, gpu::kLightTreeMaxDepth);
    std::uint32_t row = header.x;
    for (std::uint32_t d = 0; d < leaf.w; ++d) {
      ASSERT_NE(tree[row].refs.y, gpu::kInvalidIndex) << set.names[i] << ": the trail runs past a leaf";
      row = ((leaf.z >> d) & 1u) != 0u ? tree[row].refs.y : tree[row].refs.x;
    }
    EXPECT_EQ(row, 1u + i) << set.names[i];
    // Every node on the way bounds the light: its sphere, its cone and its spread, so a light
    // that can light a point leaves no ancestor of importance 0 there.
    const auto& light = tree[1 + i];
    row = header.x;
    for (std::uint32_t d = 0; d < leaf.w; ++d) {
      const auto& node = tree[row];
      const float gap = glm::length(glm::vec3(light.sphere) - glm::vec3(node.sphere)) + light.sphere.w;
      EXPECT_LE(gap, node.sphere.w * (1.0f + 1e-5f) + 1e-5f) << set.names[i] << " outside row " << row;
      if (node.cone.w > -1.0f) {
        ASSERT_GT(light.cone.w, -1.0f) << set.names[i] << ": a cone of every direction inside a narrower one";
        const double between = std::acos(cosOfAngleBetween(glm::vec3(light.cone), glm::vec3(node.cone)));
        EXPECT_LE(between + std::acos(light.cone.w), std::acos(node.cone.w) + 1e-4) << set.names[i] << " row " << row;
      }
      EXPECT_LE(node.emission.y, light.emission.y) << "the spread theta_e only widens upwards";
      if (light.emission.z != 0.0f) {
        EXPECT_NE(node.emission.z, 0.0f) << "a spot below makes the node uniform in its cone";
      }
      row = ((leaf.z >> d) & 1u) != 0u ? node.refs.y : node.refs.x;
    }
  }
  EXPECT_EQ(internal + 1, bounded) << "a binary tree with one light per leaf";
  std::printf("[ tree     ] %zu lights, %zu in the tree, depth %u\n", set.size(), bounded, header.w);
  double boundedPower = 0.0;
  for (const auto& l : set.lights)
    if (!render::isUnboundedLight(l.info.x)) boundedPower += l.params.y;
  EXPECT_NEAR(tree[header.x].emission.x, boundedPower, 1e-5) << "the root holds the power of all but the suns";
}

TEST(LightTree, LeavesStayWithinTheTrailBitsWhenTheLightsPileUpOrThinOut) {
  // 3000 lights in one place (no split separates them) and 200 on a line at distances 2^(k/4)
  // with powers growing as fast (a cost that peels one light at a time): no leaf deeper than 32.
  std::vector<gpu::GpuLight> lights;
  for (int i = 0; i < 3200; ++i) {
    gpu::GpuLight l{};
    l.info = glm::uvec4(gpu::kLightPoint, 0, 0, 0);
    l.position = i < 3000 ? glm::vec4(1.0f, 2.0f, 3.0f, 0.0f) : glm::vec4(std::exp2(float(i - 3000) / 4.0f), 0, 0, 0);
    l.params.y = i < 3000 ? 1e-4f : 1e-7f * std::pow(4.0f, float(i - 3000) / 20.0f);
    lights.push_back(l);
  }
  const Tree tree = render::buildLightTree(lights);
  EXPECT_LE(tree[0].refs.w, gpu::kLightTreeMaxDepth);
  for (std::size_t i = 0; i < lights.size(); ++i) EXPECT_LE(tree[1 + i].refs.w, gpu::kLightTreeMaxDepth);
  double sum = 0.0;
  for (std::uint32_t i = 0; i < lights.size(); ++i) sum += render::lightTreePdf(tree, lights, i, {0, 5, 0}, {0, -1, 0});
  EXPECT_NEAR(sum, 1.0, 1e-4);
}

// The descent's outcomes at p, n found another way: the probability flowing from the root into
// every node (each child takes its share of its parent's), collected at the leaves; the last
// entry is the share that ends nowhere, at a node whose two children cannot light p although
// their parent's looser bound could (the descent then returns no light: a wasted sample, as in
// pbrt-v4). Unbounded lights get 1 / shares each.
std::vector<double> outcomeProbabilities(const Tree& tree, const std::vector<gpu::GpuLight>& lights, glm::vec3 p,
                                         glm::vec3 n) {
  std::vector<double> out(lights.size() + 1, 0.0);
  auto importance = [&](std::uint32_t row) {
    return double(render::boundsImportance(render::importanceBounds(tree[row]), p, n));
  };
  const glm::uvec4 header = tree[0].refs;
  const bool lit = header.x != gpu::kInvalidIndex && importance(header.x) > 0.0;
  const double shares = double(header.y) + (lit ? 1.0 : 0.0);
  if (shares == 0.0) return out;
  for (std::uint32_t k = 0; k < header.y; ++k) out[tree[1 + header.z + k].refs.x] = 1.0 / shares;
  if (!lit) return out;
  std::vector<std::pair<std::uint32_t, double>> stack{{header.x, 1.0 / shares}};
  while (!stack.empty()) {
    auto [row, mass] = stack.back();
    stack.pop_back();
    const glm::uvec4 refs = tree[row].refs;
    if (refs.y == gpu::kInvalidIndex) {
      out[refs.x] += mass;
      continue;
    }
    const double a = importance(refs.x), b = importance(refs.y);
    if (a + b == 0.0) {
      out.back() += mass;
      continue;
    }
    stack.push_back({refs.x, mass * a / (a + b)});
    stack.push_back({refs.y, mass * b / (a + b)});
  }
  return out;
}

TEST(LightTree, PdfsSumToOneAndEveryLightThatCanLightAPointMayBeChosen) {
  const render::LightSet set = render::buildLightSet(mixedLights());
  const Tree tree = render::buildLightTree(set.lights);
  std::size_t lit = 0;
  double wasted = 0.0, worstWasted = 0.0;
  for (const Point& pt : randomPoints(3000, 5)) {
    const std::vector<double> outcomes = outcomeProbabilities(tree, set.lights, pt.p, pt.n);
    double sum = outcomes.back();
    wasted += outcomes.back() / 3000.0;
    worstWasted = std::max(worstWasted, outcomes.back());
    bool any = false;
    for (std::uint32_t i = 0; i < set.size(); ++i) {
      const float pdf = render::lightTreePdf(tree, set.lights, i, pt.p, pt.n);
      EXPECT_NEAR(pdf, outcomes[i], 1e-5 * outcomes[i]) << "the pdf along the trail is the flow into the leaf";
      sum += pdf;
      const bool reaches = render::isUnboundedLight(set.lights[i].info.x)
                               ? set.lights[i].params.y > 0.0f
                               : render::lightImportance(set.lights[i], pt.p, pt.n) > 0.0f;
      any = any || reaches;
      // Unbiased: a light whose own bound says it may light p has a chance to be picked there.
      if (reaches) {
        EXPECT_GT(pdf, 0.0f) << set.names[i] << " at " << pt.p.x << "," << pt.p.y << "," << pt.p.z;
      }
    }
    lit += any;
    EXPECT_NEAR(sum, any ? 1.0 : 0.0, 2e-5) << "the lights' pdfs and the wasted share";
  }
  EXPECT_EQ(lit, 3000u) << "the suns reach every point";
  std::printf("[ waste    ] light tree: descents that end at no light: %.2f %% on average, %.1f %% at worst\n",
              100.0 * wasted, 100.0 * worstWasted);
}

// Counts of the descent's picks at one point (kInvalidIndex: no light) against n x pdf, the
// remainder of the pdfs' sum expected as no light.
ChiSquare selectionChiSquare(const std::vector<std::uint32_t>& picks, const std::vector<float>& pdfs) {
  std::vector<double> observed(pdfs.size() + 1, 0.0), expected(pdfs.size() + 1, 0.0);
  for (std::uint32_t l : picks) observed[std::min<std::size_t>(l, pdfs.size())] += 1.0;
  double sum = 0.0;
  for (std::size_t i = 0; i < pdfs.size(); ++i) {
    expected[i] = double(pdfs[i]) * double(picks.size());
    sum += pdfs[i];
  }
  expected.back() = std::max(0.0, 1.0 - sum) * double(picks.size());
  return chiSquareTest(observed, expected);
}

TEST(LightTree, DescentPicksEachLightAsOftenAsItsPdfSaysOnTheCpu) {
  const render::LightSet set = render::buildLightSet(mixedLights());
  const Tree tree = render::buildLightTree(set.lights);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (const Point& pt : randomPoints(4, 9)) {
    std::vector<float> pdfs(set.size());
    for (std::uint32_t i = 0; i < set.size(); ++i) pdfs[i] = render::lightTreePdf(tree, set.lights, i, pt.p, pt.n);
    std::vector<std::uint32_t> picks;
    for (int k = 0; k < 400'000; ++k) {
      const render::LightPick pick = render::selectLightFromTree(tree, uni(rng), pt.p, pt.n);
      if (pick.probability > 0.0f) {
        ASSERT_EQ(pick.probability, pdfs[pick.light]) << "the descent's probability is the pdf walk's";
      }
      picks.push_back(pick.probability > 0.0f ? pick.light : gpu::kInvalidIndex);
    }
    const ChiSquare chi = selectionChiSquare(picks, pdfs);
    EXPECT_TRUE(chi.passed()) << "chi2 = " << chi.value << ", dof " << chi.dof << ", threshold " << chi.threshold;
    std::printf("[ chi2     ] light tree (CPU): %.1f (dof %d, threshold %.1f at p = 1e-4)\n", chi.value, chi.dof,
                chi.threshold);
  }
}

// ---- The production lights.glsl on the GPU

struct TreeCase {
  glm::vec4 p; // xyz, w = u
  glm::vec4 n; // xyz, w = asked light (uint bits)
};

class LightTreeShader : public GpuTest {
protected:
  std::vector<glm::vec4> run(const render::LightSet& set, const Tree& tree, const std::vector<TreeCase>& cases) {
    gpu::Kernel kernel(context(), gpu::storageKernelDesc("light_tree_test", kSpirv_light_tree_test, 5, 16));
    gpu::Buffer in = gpu::uploadArray(context(), cases, "test.cases");
    gpu::Buffer out(context(), cases.size() * sizeof(glm::vec4), vk::BufferUsageFlagBits::eStorageBuffer, "test.results");
    gpu::Buffer lights = gpu::uploadArray(context(), set.lights, "test.lights");
    gpu::Buffer emitters = gpu::uploadArray(context(), set.emitters, "test.emitters");
    gpu::Buffer nodes = gpu::uploadArray(context(), tree, "test.tree");
    kernel.bind(0, in);
    kernel.bind(1, out);
    kernel.bind(2, lights);
    kernel.bind(3, emitters);
    kernel.bind(4, nodes);
    const glm::uvec4 push(static_cast<std::uint32_t>(cases.size()), static_cast<std::uint32_t>(set.size()), 0, 0);
    context().submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
      kernel.dispatch(cmd, gpu::groupsFor(cases.size(), gpu::kWorkgroupSize1D), 1, 1, push);
    });
    return out.download<glm::vec4>(context());
  }
  static std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }
};

TEST_F(LightTreeShader, GpuPicksAndPdfsAreTheCpuTwinsAndSumToOne) {
  const render::LightSet set = render::buildLightSet(mixedLights());
  const Tree tree = render::buildLightTree(set.lights);
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const auto points = randomPoints(200, 17);
  std::vector<TreeCase> cases;
  for (const Point& pt : points)
    for (std::uint32_t i = 0; i < set.size(); ++i)
      cases.push_back({glm::vec4(pt.p, uni(rng)), glm::vec4(pt.n, std::bit_cast<float>(i))});
  const auto gpu = run(set, tree, cases);
  std::size_t samePick = 0;
  double worstPdf = 0.0;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const glm::vec3 p(cases[k].p), n(cases[k].n);
    const std::uint32_t asked = bits(cases[k].n.w);
    const float cpuPdf = render::lightTreePdf(tree, set.lights, asked, p, n);
    worstPdf = std::max(worstPdf, std::abs(double(gpu[k].z) - cpuPdf) / std::max(double(cpuPdf), 1e-6));
    const render::LightPick pick = render::selectLightFromTree(tree, cases[k].p.w, p, n);
    samePick += (gpu[k].y > 0.0f ? bits(gpu[k].x) : gpu::kInvalidIndex) ==
                (pick.probability > 0.0f ? pick.light : gpu::kInvalidIndex);
    // On the GPU too, the descent's probability is exactly what the pdf walk gives.
    EXPECT_EQ(gpu[k].y, gpu[k].w) << k;
  }
  // lavapipe's division and square root are not bit-exact to the CPU's: pdfs agree to a few
  // units in the last place per level, and a u within that of a child's boundary may go the other
  // way.
  EXPECT_LT(worstPdf, 1e-4);
  EXPECT_GE(double(samePick), 0.999 * double(cases.size()));
  std::printf("[ twin     ] light tree GPU vs CPU: pdf within %.2g (relative), same light %zu of %zu\n", worstPdf,
              samePick, cases.size());
  for (std::size_t pt = 0; pt < points.size(); ++pt) {
    double sum = outcomeProbabilities(tree, set.lights, points[pt].p, points[pt].n).back(); // wasted share
    for (std::size_t i = 0; i < set.size(); ++i) sum += gpu[pt * set.size() + i].z;
    EXPECT_NEAR(sum, 1.0, 1e-4) << "point " << pt << ": the GPU's pdfs and the wasted share";
  }
}

TEST_F(LightTreeShader, GpuDescentPicksEachLightAsOftenAsItsPdfSays) {
  const render::LightSet set = render::buildLightSet(mixedLights());
  const Tree tree = render::buildLightTree(set.lights);
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (const Point& pt : randomPoints(3, 2)) {
    std::vector<TreeCase> cases;
    for (int k = 0; k < 300'000; ++k)
      cases.push_back({glm::vec4(pt.p, uni(rng)), glm::vec4(pt.n, std::bit_cast<float>(static_cast<std::uint32_t>(k % set.size())))});
    const auto gpu = run(set, tree, cases);
    std::vector<float> pdfs(set.size());
    std::vector<std::uint32_t> picks;
    for (std::size_t k = 0; k < cases.size(); ++k) {
      if (k < set.size()) pdfs[k] = gpu[k].z; // the GPU's own pdf of light k
      picks.push_back(gpu[k].y > 0.0f ? bits(gpu[k].x) : gpu::kInvalidIndex);
    }
    const ChiSquare chi = selectionChiSquare(picks, pdfs);
    EXPECT_TRUE(chi.passed()) << "chi2 = " << chi.value << ", dof " << chi.dof << ", threshold " << chi.threshold;
    std::printf("[ chi2     ] light tree (GPU): %.1f (dof %d, threshold %.1f at p = 1e-4)\n", chi.value, chi.dof,
                chi.threshold);
  }
}

// ---- Many lights in an image

// A floor under 150 point lights: 130 dim ones (1 to 3 cd) within 3 m of the origin at 0.5 to
// 1.5 m, 20 bright ones (2000 to 8000 cd) 40 to 60 m away: by power the near lights, which give
// about half the light at the origin, are picked once in 500 samples.
scene::Scene manyPointLights() {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  SceneBuilder b;
  b.quad({-1000, 0, -1000}, {0, 0, 2000}, {2000, 0, 0}, b.lambertian(glm::vec3(0.5f)));
  for (int i = 0; i < 130; ++i) {
    const float r = 3.0f * std::sqrt(uni(rng)), phi = 2.0f * std::numbers::pi_v<float> * uni(rng);
    b.pointLight({r * std::cos(phi), 0.5f + uni(rng), r * std::sin(phi)}, glm::vec3(1.0f), 1.0f + 2.0f * uni(rng),
                 "near" + std::to_string(i));
  }
  for (int i = 0; i < 20; ++i) {
    const float r = 40.0f + 20.0f * uni(rng), phi = 2.0f * std::numbers::pi_v<float> * uni(rng);
    b.pointLight({r * std::cos(phi), 5.0f + 15.0f * uni(rng), r * std::sin(phi)}, glm::vec3(1.0f),
                 2000.0f + 6000.0f * uni(rng), "far" + std::to_string(i));
  }
  return b.build();
}

TEST_F(LightTreeShader, ManyPointLightsRenderToTheAnalyticRadianceWithLessNoiseThanSelectionByPower) {
  const scene::Scene s = manyPointLights();
  // The floor's radiance at the origin: albedo / pi x sum_k I_k cos(theta_k) / d_k^2.
  double expected = 0.0;
  for (const auto& l : s.punctualLights) {
    const glm::dvec3 d = glm::dvec3(l.position);
    expected += 0.5 / std::numbers::pi * l.intensity * (d.y / glm::length(d)) / glm::dot(d, d);
  }
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  double spread[2] = {}, mean[2] = {}, stdError[2] = {};
  for (auto sampling : {render::LightSampling::Spatial, render::LightSampling::Area}) {
    render::ObscuranceSettings settings;
    settings.width = settings.height = 32;
    settings.spp = 16;
    settings.camera = lookCamera({0, 0.2f, 0}, {0, -1, 0}, {0, 0, -1}, 0.002f); // every pixel sees the origin
    settings.shadowRays = 4;
    settings.obscuranceRays = 0;
    settings.lightSampling = sampling;
    auto r = renderObscurances(context(), s, tree, settings);
    ASSERT_EQ(r.lights.size(), 150u);
    EXPECT_EQ(r.stats.truncatedTraversals, 0u);
    // Every pixel is an independent estimate of the same radiance: the spread of the pixels is the
    // seed-to-seed noise of one, and the mean's standard error follows from it.
    const int channel = r.image.channelIndex("direct.G");
    double sum = 0.0, sum2 = 0.0;
    const int n = r.image.width * r.image.height;
    for (int y = 0; y < r.image.height; ++y)
      for (int x = 0; x < r.image.width; ++x) {
        const double v = r.image.at(x, y, channel);
        ASSERT_TRUE(std::isfinite(v));
        sum += v;
        sum2 += v * v;
      }
    const int k = int(sampling);
    mean[k] = sum / n;
    spread[k] = std::sqrt(std::max(0.0, sum2 / n - mean[k] * mean[k]) * n / (n - 1));
    stdError[k] = spread[k] / std::sqrt(double(n));
    EXPECT_NEAR(mean[k], expected, 4.0 * stdError[k] + 1e-5 * expected) << (k == 0 ? "tree" : "by power");
  }
  EXPECT_NEAR(mean[0], mean[1], 4.0 * std::hypot(stdError[0], stdError[1]));
  // Measured: the tree's pixels spread about 40 times less than selection by power's.
  EXPECT_LT(spread[0], 0.2 * spread[1]) << "tree " << spread[0] << " by power " << spread[1];
  std::printf("[ noise    ] 150 point lights: tree %.4g, by power %.4g per pixel (ratio %.1f); mean %.5g, %.5g, "
              "analytic %.5g\n",
              spread[0], spread[1], spread[1] / spread[0], mean[0], mean[1], expected);
}

// A glossy floor under 100 small square lamps (more than kMaxSpatialLights): the path tracer's MIS
// weighs each lobe ray that hits a lamp by the tree's pdf of that lamp (lightTreePdf), so a wrong
// pdf biases MIS against BSDF sampling alone, which uses no light pdf at all. The two agree within
// 4 standard errors of the per-pixel differences (independent seeds), over the image and each
// quadrant.
TEST_F(LightTreeShader, PathTracerMisWithTreePdfsAgreesWithBsdfSamplingUnderManyLamps) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  SceneBuilder b;
  b.quad({-3, 0, -3}, {0, 0, 6}, {6, 0, 0}, b.glossy(glm::vec3(0.6f), 0.0f, 0.3f)); // faces +y
  for (int i = 0; i < 100; ++i) {
    const float a = 0.03f + 0.07f * uni(rng);
    const glm::vec3 c(3.0f * uni(rng) - 1.5f, 0.7f + 0.5f * uni(rng), 3.0f * uni(rng) - 1.5f);
    b.quad(c - glm::vec3(a, 0, a), {2 * a, 0, 0}, {0, 0, 2 * a}, b.lambertian(glm::vec3(0.0f), glm::vec3(2.0f + 18.0f * uni(rng))),
           "lamp" + std::to_string(i)); // faces -y
  }
  const scene::Scene s = b.build();
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  render::PathTraceSettings settings;
  settings.width = settings.height = 32;
  settings.maxDepth = 1;
  settings.camera = lookCamera({0, 0.6f, 2.2f}, {0, -0.35f, -1.0f}, {0, 1, 0}, 0.9f);
  std::vector<std::vector<double>> images;
  for (auto strategy : {render::PathStrategy::Mis, render::PathStrategy::BsdfOnly}) {
    settings.strategy = strategy;
    settings.seed = 3 + static_cast<std::uint32_t>(strategy);
    settings.spp = strategy == render::PathStrategy::BsdfOnly ? 512 : 64;
    auto r = renderPathTraced(context(), s, tree, settings);
    EXPECT_EQ(r.nonFiniteSamples, 0u);
    const int g = r.image.channelIndex("combined.G");
    std::vector<double> v;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) v.push_back(r.image.at(x, y, g));
    images.push_back(v);
  }
  for (int q = -1; q < 4; ++q) {
    double sum = 0.0, sum2 = 0.0, reference = 0.0;
    int n = 0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        if (q >= 0 && (x / 16 + 2 * (y / 16)) != q) continue;
        const double d = images[0][y * 32 + x] - images[1][y * 32 + x];
        sum += d;
        sum2 += d * d;
        reference += images[1][y * 32 + x];
        ++n;
      }
    const double mean = sum / n, stdError = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1));
    EXPECT_NEAR(mean, 0.0, 4.0 * stdError) << "quadrant " << q << " (-1: all), BSDF sampling's mean " << reference / n;
    if (q < 0) std::printf("[ mis      ] 100 lamps: MIS - BSDF sampling %.4g +- %.4g (mean %.4g)\n", mean, stdError, reference / n);
  }
}

} // namespace
} // namespace obscura::test
