// The path-tracing reference [RTO §5.1, SPEC §1.5] against closed forms and against the
// obscurance renderer's direct light:
// - furnace: inside a closed sphere of albedo a and emission L_e the radiance is
//   L_e (1 - a^(d+1)) / (1 - a) for depth d [SPEC §5], for every d and with Russian roulette;
// - a long path (hundreds of vertices) in a closed box stays exact and never reaches lavapipe's
//   loop limiter;
// - depth 1 on the Cornell box = obscurance's "direct" + "emission" AOVs (pure light sampling);
// - MIS, light sampling alone and BSDF sampling alone agree (small light over a glossy floor);
// - determinism, no NaN/inf, a scene without lights is black and traces no shadow ray.
// Statistical tolerances come from the noise measured in the same images (the spread over pixels
// of values with the same expectation), never from a guessed constant.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "render/one_shot.h"
#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "scene/gltf_loader.h"
#include "shared/host_device.h"

namespace obscura::test {
namespace {

// A mean and its standard error.
struct Estimate {
  double mean = 0.0, stdError = 0.0;
};

// Mean of values with one expectation, standard error from their spread.
Estimate estimate(const std::vector<double>& v) {
  double sum = 0.0, sum2 = 0.0;
  for (double x : v) sum += x;
  const double n = static_cast<double>(v.size()), mean = sum / n;
  for (double x : v) sum2 += (x - mean) * (x - mean);
  return {mean, std::sqrt(sum2 / (n - 1.0) / n)};
}

// Channel c of every pixel (c = 3: the mean of R, G, B).
std::vector<double> channelValues(const io::Image& image, const std::string& prefix, int c) {
  std::vector<double> out;
  int r = image.channelIndex(prefix + ".R");
  EXPECT_GE(r, 0) << prefix;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      out.push_back(c < 3 ? image.at(x, y, r + c)
                          : (image.at(x, y, r) + image.at(x, y, r + 1) + image.at(x, y, r + 2)) / 3.0);
  return out;
}

class PathTrace : public GpuTest {
protected:
  test::PathTraceResult render(const scene::Scene& s, const render::PathTraceSettings& settings) {
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    auto result = test::renderPathTraced(context(), s, tree, settings);
    EXPECT_EQ(result.stats.truncatedTraversals, 0u) << "the loop limiter must never cut a path";
    EXPECT_EQ(result.nonFiniteSamples, 0u);
    for (float v : result.image.pixels) EXPECT_TRUE(std::isfinite(v));
    EXPECT_TRUE(result.stats.passes.contains("pathtrace"));
    return result;
  }
};

// A sphere of radius 1 around the origin from a subdivided icosahedron (20 * 4^n triangles),
// wound so that the front faces point INWARD: its one-sided emission lights the inside only
// [SPEC §5]. Every triangle has its own vertices with its face normal, so shading and geometric
// normals agree and the enclosure conserves energy exactly (interpolated normals would not).
scene::Scene furnaceSphere(float albedo, float emission, int subdivisions) {
  SceneBuilder b;
  std::uint32_t material = b.lambertian(glm::vec3(albedo), glm::vec3(emission));
  scene::Scene s = b.build();
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p = glm::normalize(p);
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::vector<glm::uvec3> next;
    for (const auto& tri : f) {
      std::uint32_t m[3];
      for (int e = 0; e < 3; ++e) {
        v.push_back(glm::normalize(v[tri[e]] + v[tri[(e + 1) % 3]])); // duplicates are harmless here
        m[e] = static_cast<std::uint32_t>(v.size() - 1);
      }
      next.push_back({tri.x, m[0], m[2]});
      next.push_back({m[0], tri.y, m[1]});
      next.push_back({m[2], m[1], tri.z});
      next.push_back({m[0], m[1], m[2]});
    }
    f = next;
  }
  // Shared midpoints computed twice are bit-identical (same operands, same order), so the mesh
  // stays watertight.
  s.lightGroups.push_back({.name = "sphere", .triangles = {}, .emission = glm::vec3(emission)});
  for (const auto& tri : f) {
    glm::vec3 a = v[tri.x], c = v[tri.z], bb = v[tri.y];
    // Outward CCW as listed; swap two vertices so the front face (CCW normal) points inward.
    glm::vec3 n = glm::normalize(glm::cross(c - a, bb - a));
    auto base = static_cast<std::uint32_t>(s.positions.size());
    for (glm::vec3 p : {a, c, bb}) {
      s.positions.push_back(p);
      s.normals.push_back(n);
      s.uvs.push_back(glm::vec2(0.0f));
      s.bounds.grow(p);
    }
    s.lightGroups[0].triangles.push_back(static_cast<std::uint32_t>(s.triangles.size()));
    s.triangles.push_back({base, base + 1, base + 2});
    s.triangleMaterial.push_back(material);
    s.triangleLightGroup.push_back(0u);
  }
  return s;
}

double furnaceRadiance(double emission, double albedo, std::uint32_t depth) {
  return emission * (1.0 - std::pow(albedo, depth + 1.0)) / (1.0 - albedo);
}

// The closed cube [-1, 1]^3, every face facing inward, all one emissive Lambertian light group.
scene::Scene furnaceBox(float albedo, float emission) {
  SceneBuilder b;
  auto m = b.lambertian(glm::vec3(albedo), glm::vec3(emission));
  b.quad({-1, -1, -1}, {0, 0, 2}, {2, 0, 0}, m, "box"); // y = -1, faces +y
  b.quad({-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, m, "box");  // y = +1, faces -y
  b.quad({-1, -1, -1}, {0, 2, 0}, {0, 0, 2}, m, "box"); // x = -1, faces +x
  b.quad({1, -1, -1}, {0, 0, 2}, {0, 2, 0}, m, "box");  // x = +1, faces -x
  b.quad({-1, -1, -1}, {2, 0, 0}, {0, 2, 0}, m, "box"); // z = -1, faces +z
  b.quad({-1, -1, 1}, {0, 2, 0}, {2, 0, 0}, m, "box");  // z = +1, faces -z
  return b.build();
}

render::PathTraceSettings inside(std::uint32_t size, std::uint32_t spp, std::uint32_t depth) {
  render::PathTraceSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.maxDepth = depth;
  s.camera = lookCamera({0.1f, -0.2f, 0.05f}, {0.3f, 0.2f, -1.0f}, {0, 1, 0}, 1.2f);
  return s;
}

// Every pixel has the same expectation, so the pixel spread gives the standard error of the mean.
// Tolerance: 4 standard errors, plus 1e-5 relative for float summation.
TEST_F(PathTrace, FurnaceMatchesTheClosedFormForEveryDepth) {
  const float albedo = 0.5f, emission = 1.0f;
  scene::Scene s = furnaceSphere(albedo, emission, 3); // 1280 triangles
  struct Case {
    std::uint32_t depth;
    render::PathStrategy strategy;
  };
  for (Case c : {Case{1, render::PathStrategy::Mis}, Case{2, render::PathStrategy::Mis}, Case{3, render::PathStrategy::Mis},
                 Case{64, render::PathStrategy::Mis}, Case{2, render::PathStrategy::LightOnly},
                 Case{2, render::PathStrategy::BsdfOnly}, Case{64, render::PathStrategy::BsdfOnly}}) {
    auto settings = inside(32, 16, c.depth);
    settings.strategy = c.strategy;
    auto r = render(s, settings);
    const double expected = furnaceRadiance(emission, albedo, c.depth);
    for (int ch = 0; ch < 3; ++ch) {
      Estimate e = estimate(channelValues(r.image, "combined", ch));
      EXPECT_NEAR(e.mean, expected, 4.0 * e.stdError + 1e-5 * expected)
          << "depth " << c.depth << " strategy " << int(c.strategy) << " channel " << ch << " (standard error "
          << e.stdError << ")";
      EXPECT_LT(e.stdError, 0.01 * expected) << "the test must resolve 1% of the answer";
    }
  }
}

// 200 scattering vertices per path, without Russian roulette, in a closed white-ish box: the
// value stays exact (a silent cut-off would lose the tail) and no traversal is truncated.
TEST_F(PathTrace, LongPathsInAClosedBoxNeverReachTheLoopLimiter) {
  const float albedo = 0.9f, emission = 1.0f;
  scene::Scene s = furnaceBox(albedo, emission);
  auto settings = inside(16, 4, 200);
  settings.rrDepth = settings.maxDepth; // no roulette: every path really has 200 vertices
  auto r = render(s, settings);
  EXPECT_EQ(r.stats.truncatedTraversals, 0u);
  // Camera ray + 200 bounce rays (the last vertex's continuation is not traced: 199) + up to 200
  // shadow rays per path.
  const std::uint64_t paths = 16 * 16 * 4;
  EXPECT_GE(r.stats.passes.at("pathtrace").rays, paths * 200);
  const double expected = furnaceRadiance(emission, albedo, settings.maxDepth);
  Estimate e = estimate(channelValues(r.image, "combined", 3));
  EXPECT_NEAR(e.mean, expected, 4.0 * e.stdError + 1e-4 * expected) << "standard error " << e.stdError;
  // And with roulette from depth 3 the mean is unchanged (unbiased), only noisier.
  settings.rrDepth = 3;
  settings.spp = 16;
  auto rr = render(s, settings);
  Estimate er = estimate(channelValues(rr.image, "combined", 3));
  EXPECT_NEAR(er.mean, expected, 4.0 * er.stdError + 1e-4 * expected) << "standard error " << er.stdError;
  EXPECT_LT(rr.stats.passes.at("pathtrace").rays, r.stats.passes.at("pathtrace").rays);
}

// Differences a - b of two renders with the same expectation per pixel, over a block of pixels:
// the mean difference must be within 4.5 standard errors of 0 (spread of the differences).
void expectSameMean(const std::vector<double>& a, const std::vector<double>& b, int width, int x0, int y0, int w,
                    int h, const std::string& what) {
  std::vector<double> d;
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) d.push_back(a[y * width + x] - b[y * width + x]);
  Estimate e = estimate(d);
  EXPECT_LE(std::abs(e.mean), 4.5 * e.stdError + 1e-6) << what << " block (" << x0 << "," << y0 << ") " << w << "x"
                                                       << h << ": mean difference " << e.mean << ", standard error "
                                                       << e.stdError;
}

TEST_F(PathTrace, DirectLightOnTheCornellBoxMatchesTheObscuranceRenderersDirectAov) {
  scene::Scene s = scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"));
  const std::uint32_t size = 32, spp = 128;
  render::PathTraceSettings pt;
  pt.width = pt.height = size;
  pt.spp = spp;
  pt.maxDepth = 1;
  pt.camera = s.cameras.at(0);
  auto path = render(s, pt);

  render::ObscuranceSettings ob;
  ob.width = ob.height = size;
  ob.spp = spp; // same seed and spp: the same sub-pixel positions as the path tracer's camera rays
  ob.camera = pt.camera;
  ob.shadowRays = 8;
  ob.obscuranceRays = 0;
  bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  auto ref = test::renderObscurances(context(), s, tree, ob);
  ASSERT_EQ(ref.stats.truncatedTraversals, 0u);

  double sumSq = 0.0, sumRef = 0.0;
  for (int ch = 0; ch < 3; ++ch) {
    auto a = channelValues(path.image, "combined", ch);
    auto direct = channelValues(ref.image, "direct", ch), emitted = channelValues(ref.image, "emission", ch);
    std::vector<double> b(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      b[i] = direct[i] + emitted[i];
      sumSq += (a[i] - b[i]) * (a[i] - b[i]);
      sumRef += b[i];
    }
    const std::string what = std::string("channel ") + "RGB"[ch];
    expectSameMean(a, b, size, 0, 0, size, size, what);
    for (int by = 0; by < 4; ++by)
      for (int bx = 0; bx < 4; ++bx) expectSameMean(a, b, size, bx * 8, by * 8, 8, 8, what);
  }
  const double rmse = std::sqrt(sumSq / (3.0 * size * size)), meanRef = sumRef / (3.0 * size * size);
  // Per-pixel agreement: both are noisy estimates of the same image (measured: RMSE 1.9% of the
  // mean 0.088, all noise); a per-pixel bias of a few percent anywhere would show here.
  EXPECT_LT(rmse, 0.05 * meanRef) << "RMSE " << rmse << " against a mean of " << meanRef;
}

// A small bright area light over a glossy floor, direct light only: MIS, light sampling alone and
// BSDF sampling alone estimate the same image.
TEST_F(PathTrace, MisAndEachTechniqueAloneAgreeOnAGlossyFloor) {
  SceneBuilder b;
  auto floor = b.glossy(glm::vec3(0.6f), 0.0f, 0.3f);
  auto light = b.lambertian(glm::vec3(0.0f), glm::vec3(20.0f));
  b.quad({-2, 0, -2}, {0, 0, 4}, {4, 0, 0}, floor);                      // faces +y
  b.quad({-0.25f, 1, -0.25f}, {0.5f, 0, 0}, {0, 0, 0.5f}, light, "lamp"); // faces -y
  scene::Scene s = b.build();
  render::PathTraceSettings settings;
  settings.width = settings.height = 32;
  settings.spp = 64;
  settings.maxDepth = 1;
  settings.camera = lookCamera({0, 0.6f, 1.6f}, {0, -0.45f, -1.0f}, {0, 1, 0}, 0.9f);
  std::vector<std::vector<double>> images;
  for (auto strategy : {render::PathStrategy::Mis, render::PathStrategy::LightOnly, render::PathStrategy::BsdfOnly}) {
    settings.strategy = strategy;
    settings.seed = 7 + static_cast<std::uint32_t>(strategy); // independent noise
    settings.spp = strategy == render::PathStrategy::BsdfOnly ? 256 : 64; // the noisy one gets more
    images.push_back(channelValues(render(s, settings).image, "combined", 3));
  }
  for (int other : {1, 2}) {
    const std::string what = other == 1 ? "MIS vs light sampling" : "MIS vs BSDF sampling";
    expectSameMean(images[0], images[other], 32, 0, 0, 32, 32, what);
    for (int by = 0; by < 2; ++by)
      for (int bx = 0; bx < 2; ++bx) expectSameMean(images[0], images[other], 32, bx * 16, by * 16, 16, 16, what);
  }
  Estimate m = estimate(images[0]);
  EXPECT_GT(m.mean, 0.0);
}

TEST_F(PathTrace, SameSeedSameImage) {
  scene::Scene s = scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"));
  render::PathTraceSettings settings;
  settings.width = settings.height = 16;
  settings.spp = 2;
  settings.camera = s.cameras.at(0);
  auto a = render(s, settings), c = render(s, settings);
  ASSERT_EQ(a.image.pixels.size(), c.image.pixels.size());
  for (std::size_t i = 0; i < a.image.pixels.size(); ++i) ASSERT_EQ(a.image.pixels[i], c.image.pixels[i]) << i;
  settings.seed = 2;
  auto d = render(s, settings);
  EXPECT_NE(a.image.pixels, d.image.pixels);
}

// No light at all: black, finite, and exactly the camera ray and one bounce ray per path (the
// plane seen from above; the bounce leaves the scene): not a single shadow ray.
TEST_F(PathTrace, ASceneWithoutLightsIsBlackAndTracesNoShadowRay) {
  SceneBuilder b;
  auto m = b.lambertian(glm::vec3(0.8f));
  b.quad({-1000, 0, -1000}, {0, 0, 2000}, {2000, 0, 0}, m);
  scene::Scene s = b.build();
  render::PathTraceSettings settings;
  settings.width = settings.height = 8;
  settings.spp = 2;
  settings.camera = lookCamera({0, 1, 0}, {0, -1, 0}, {0, 0, -1}, 1.0f);
  auto r = render(s, settings);
  for (float v : r.image.pixels) EXPECT_EQ(v, 0.0f);
  EXPECT_EQ(r.stats.passes.at("pathtrace").rays, 8u * 8u * 2u * 2u);
}

} // namespace
} // namespace obscura::test
