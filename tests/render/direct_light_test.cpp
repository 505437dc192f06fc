// The shared direct-light estimator (shaders/lib/lights.glsl, shade.glsl) [SPEC §1.3], in the
// obscurance renderer and the path tracer: both light samplings (spatial: importance, solid angle,
// MIS on glossy lobes; area: the paper's) reach the analytic form factor of a square light, the
// spatial one with less noise; glossy reflection of a small light is the same with MIS (spatial),
// without it (area) and in the path tracer; a dim lamp next to the receiver and a bright one far
// away give the same answer under both selections, the spatial one with a fraction of the noise.
//
// Every test looks at one point through a very narrow camera, so all pixels share one
// expectation and their spread gives the standard error of the mean; tolerances are 4 of those.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/obscurance_renderer.h"
#include "render/one_shot.h"
#include "render/passes/shading_inputs.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

constexpr float kHalfSize = 1000.0f; // "infinite" floor

struct Estimate {
  double mean = 0.0, stdError = 0.0, spread = 0.0; // spread: standard deviation of one pixel
};

Estimate estimate(const io::Image& image, const std::vector<std::string>& channels) {
  std::vector<int> indices;
  for (const auto& c : channels) indices.push_back(image.channelIndex(c));
  double sum = 0.0, sum2 = 0.0;
  const int n = image.width * image.height;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      double v = 0.0;
      for (int c : indices) v += image.at(x, y, c);
      sum += v;
      sum2 += v * v;
    }
  Estimate e;
  e.mean = sum / n;
  e.spread = std::sqrt(std::max(0.0, sum2 / n - e.mean * e.mean) * n / (n - 1));
  e.stdError = e.spread / std::sqrt(double(n));
  return e;
}

class DirectLight : public GpuTest {
protected:
  test::ObscuranceResult render(const scene::Scene& s, render::ObscuranceSettings settings) {
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    auto r = test::renderObscurances(context(), s, tree, settings);
    EXPECT_EQ(r.stats.truncatedTraversals, 0u);
    for (float v : r.image.pixels) EXPECT_TRUE(std::isfinite(v));
    return r;
  }
  test::PathTraceResult pathTrace(const scene::Scene& s, render::PathTraceSettings settings) {
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    auto r = test::renderPathTraced(context(), s, tree, settings);
    EXPECT_EQ(r.stats.truncatedTraversals, 0u);
    EXPECT_EQ(r.nonFiniteSamples, 0u);
    return r;
  }
};

// A camera at `height` above the origin looking straight down, so narrow that every pixel sees the
// origin (within 1e-3): direct light only (no obscurance rays).
render::ObscuranceSettings atTheOrigin(render::LightSampling sampling, std::uint32_t spp, float height = 0.5f) {
  render::ObscuranceSettings s;
  s.width = s.height = 32;
  s.spp = spp;
  s.camera = lookCamera({0, height, 0}, {0, -1, 0}, {0, 0, -1}, 0.002f);
  s.shadowRays = 4;
  s.obscuranceRays = 0;
  s.lightSampling = sampling;
  return s;
}

const char* name(render::LightSampling s) { return s == render::LightSampling::Spatial ? "spatial" : "area"; }

TEST_F(DirectLight, BothSamplingsReachTheSquareLightsFormFactorAndSolidAngleIsLessNoisy) {
  // A square emitter of half-side a at height h, facing down over the origin, unit radiance:
  // the floor's radiance is albedo * F, F = (4/pi) X/sqrt(1+X^2) atan(X/sqrt(1+X^2)), X = a/h.
  // Its two triangles seen from the origin each subtend 0.18 sr, inside the spherical warp's range.
  const float a = 0.5f, h = 0.4f, albedo = 0.5f;
  SceneBuilder b;
  auto floor = b.lambertian(glm::vec3(albedo));
  auto emitter = b.lambertian(glm::vec3(0.0f), glm::vec3(1.0f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  b.quad({-a, h, -a}, {2 * a, 0, 0}, {0, 0, 2 * a}, emitter, "square"); // faces -y
  scene::Scene s = b.build();
  const double x = a / h, q = x / std::sqrt(1.0 + x * x);
  const double expected = albedo * 4.0 / std::numbers::pi * q * std::atan(q);
  double spread[2] = {};
  for (auto sampling : {render::LightSampling::Spatial, render::LightSampling::Area}) {
    auto r = render(s, atTheOrigin(sampling, 4, 0.3f));
    Estimate e = estimate(r.image, {"direct.G"});
    EXPECT_NEAR(e.mean, expected, 4.0 * e.stdError + 1e-5 * expected) << name(sampling);
    spread[int(sampling)] = e.spread;
  }
  // Uniform in solid angle leaves only cos(theta_P) to vary; uniform by area adds cos(theta_L) / r^2.
  EXPECT_LT(spread[int(render::LightSampling::Spatial)], 0.5 * spread[int(render::LightSampling::Area)])
      << "spatial " << spread[0] << " area " << spread[1];
}

TEST_F(DirectLight, GlossyHighlightIsTheSameWithMisWithoutItAndInThePathTracer) {
  // A rough-glossy floor (GGX, roughness 0.3) under a small square light right above: the camera
  // looks straight down, so the highlight is the light's reflection. Direct + specular of the
  // obscurance renderer (spatial: light samples and the specular pass's lobe sample weighted by
  // the power heuristic; area: light samples alone) and the path tracer at depth 1 (MIS with its
  // full BSDF) estimate the same reflected radiance.
  SceneBuilder b;
  auto floor = b.glossy(glm::vec3(0.6f, 0.5f, 0.4f), 0.0f, 0.3f);
  auto emitter = b.lambertian(glm::vec3(0.0f), glm::vec3(5.0f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  const float a = 0.1f, h = 1.0f;
  b.quad({-a, h, -a}, {2 * a, 0, 0}, {0, 0, 2 * a}, emitter, "small"); // faces -y
  scene::Scene s = b.build();
  Estimate byMethod[3];
  for (auto sampling : {render::LightSampling::Spatial, render::LightSampling::Area}) {
    auto settings = atTheOrigin(sampling, 16);
    auto r = render(s, settings);
    ASSERT_TRUE(r.stats.passes.contains("specular"));
    byMethod[int(sampling)] = estimate(r.image, {"direct.G", "specular.G"});
  }
  render::PathTraceSettings pt;
  pt.width = pt.height = 32;
  pt.spp = 64;
  pt.maxDepth = 1;
  pt.camera = atTheOrigin(render::LightSampling::Spatial, 1).camera;
  byMethod[2] = estimate(pathTrace(s, pt).image, {"combined.G"});
  const char* names[3] = {"obscurance spatial (MIS)", "obscurance area (no MIS)", "path tracer"};
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      EXPECT_NEAR(byMethod[i].mean, byMethod[j].mean,
                  4.0 * std::hypot(byMethod[i].stdError, byMethod[j].stdError) + 1e-5 * byMethod[i].mean)
          << names[i] << " " << byMethod[i].mean << " against " << names[j] << " " << byMethod[j].mean;
  // The camera sees a lamp of radiance 5 through a lobe of albedo ~0.04: the answer is no zero.
  EXPECT_GT(byMethod[0].mean, 0.01);
}

// The mean of the per-pixel differences of two renders of the same scene, with its standard error
// from their spread (the pixels' own expectations cancel; each pixel is one independent sample).
Estimate meanDifference(const io::Image& a, const io::Image& b, const std::vector<std::string>& channels) {
  io::Image d = a;
  for (const auto& c : channels) {
    const int i = a.channelIndex(c);
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x) d.at(x, y, i) = a.at(x, y, i) - b.at(x, y, i);
  }
  return estimate(d, channels);
}

TEST_F(DirectLight, SpecularPathVerticesGatherTheSameMeanWithRaysScaledByThroughput) {
  // A rough dielectric floor (a few per cent of Fresnel reflection: one ray of each kind at the
  // next vertex instead of N_s and N_obs) reflects a dark rough metal wall, whose lobe reflects a
  // small lamp above the floor: the wall's vertex weighs its lobe sample against its own light
  // samples, one here, by MIS. Scaled or not, the specular light has the same mean, for fewer rays.
  SceneBuilder b;
  auto floor = b.glossy(glm::vec3(0.6f, 0.5f, 0.4f), 0.0f, 0.2f);
  auto wall = b.glossy(glm::vec3(0.3f, 0.25f, 0.2f), 1.0f, 0.25f);
  auto back = b.lambertian(glm::vec3(0.5f));
  auto emitter = b.lambertian(glm::vec3(0.0f), glm::vec3(20.0f, 15.0f, 10.0f));
  b.quad({-2, 0, -1}, {0, 0, 3}, {4, 0, 0}, floor);   // faces +y
  b.quad({-2, 0, -1}, {4, 0, 0}, {0, 2, 0}, wall);    // faces +z
  b.quad({-2, 0, 2}, {0, 2, 0}, {4, 0, 0}, back);     // faces -z, behind the camera
  b.quad({-0.3f, 1.2f, 0.2f}, {0.6f, 0, 0}, {0, 0, 0.3f}, emitter, "lamp"); // faces -y
  scene::Scene s = b.build();
  render::ObscuranceSettings settings;
  settings.width = settings.height = 32;
  settings.spp = 48;
  settings.maxDepth = 3;
  settings.camera = lookCamera({0, 0.4f, 1.5f}, {0, -0.35f, -1}, {0, 1, 0}, 0.5f);
  settings.vertexRaysByThroughput = false;
  auto perHit = render(s, settings);
  settings.vertexRaysByThroughput = true;
  auto scaled = render(s, settings);
  ASSERT_TRUE(perHit.stats.passes.contains("specular"));
  const std::vector<std::string> specular = {"specular.R", "specular.G", "specular.B"};
  const Estimate difference = meanDifference(scaled.image, perHit.image, specular);
  const double mean = estimate(perHit.image, specular).mean;
  EXPECT_GT(mean, 0.02) << "the camera sees light along the specular paths";
  EXPECT_NEAR(difference.mean, 0.0, 4.0 * difference.stdError + 1e-5 * mean)
      << "scaled minus per-hit " << difference.mean << " of " << mean;
  // Most vertices lie on the wall, seen through the floor's Fresnel reflection.
  EXPECT_LT(scaled.stats.passes.at("specular").rays, perHit.stats.passes.at("specular").rays / 2);
}

TEST_F(DirectLight, DimLampNearbyAndBrightLampFarAwayAgreeAndSpatialSelectionIsLessNoisy) {
  // A lamp of power 1 at 0.3 above the origin and one of 10^4 times its power 30 away to the side:
  // by power the near lamp, which gives most of the light, is picked once in 10^4 samples (the
  // paper's fireflies); by importance at the point it is picked nearly always.
  SceneBuilder b;
  auto floor = b.lambertian(glm::vec3(0.5f));
  auto dim = b.lambertian(glm::vec3(0.0f), glm::vec3(1.0f));
  auto bright = b.lambertian(glm::vec3(0.0f), glm::vec3(1.0f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  b.quad({-0.05f, 0.3f, -0.05f}, {0.1f, 0, 0}, {0, 0, 0.1f}, dim, "dim");            // 0.01 m^2, faces -y
  b.quad({30.0f, 0.5f, -5.0f}, {0, 0, 10.0f}, {0, 10.0f, 0}, bright, "bright");      // 100 m^2, faces -x
  scene::Scene s = b.build();
  Estimate e[2];
  for (auto sampling : {render::LightSampling::Spatial, render::LightSampling::Area}) {
    auto r = render(s, atTheOrigin(sampling, 64, 0.2f)); // the camera under the dim lamp
    e[int(sampling)] = estimate(r.image, {"direct.G"});
  }
  const auto spatial = e[int(render::LightSampling::Spatial)], area = e[int(render::LightSampling::Area)];
  EXPECT_NEAR(spatial.mean, area.mean, 4.0 * std::hypot(spatial.stdError, area.stdError))
      << "spatial " << spatial.mean << " area " << area.mean;
  EXPECT_LT(spatial.spread, 0.1 * area.spread) << "spatial " << spatial.spread << " area " << area.spread;
}

TEST_F(DirectLight, SkyOverAnOpenFloorIsExactInBothMethods) {
  // A uniform sky of radiance L over an infinite Lambertian floor of albedo a: the floor's
  // radiance is a L (irradiance pi L). Cosine-distributed sky samples make every shadow ray's
  // estimate exactly a L, in the obscurance renderer and in the path tracer's NEE, whose MIS with
  // the equally cosine-distributed BSDF sample splits it in two exact halves. A camera ray that
  // leaves the scene sees L.
  SceneBuilder b;
  auto floor = b.lambertian(glm::vec3(0.5f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  scene::Scene s = b.build();
  const glm::vec3 sky(0.5f, 1.0f, 2.0f);
  s.background = sky;
  auto settings = atTheOrigin(render::LightSampling::Spatial, 2);
  auto r = render(s, settings);
  ASSERT_EQ(r.lights.size(), 1u);
  EXPECT_EQ(r.lights.names[0], "background");
  for (int c = 0; c < 3; ++c) {
    Estimate e = estimate(r.image, {std::string("direct.") + "RGB"[c]});
    EXPECT_NEAR(e.mean, 0.5 * sky[c], 1e-5 * sky[c]) << c;
    EXPECT_LT(e.spread, 1e-5 * sky[c]) << c;
  }
  // Looking up: every pixel is sky.
  settings.camera = lookCamera({0, 1, 0}, {0, 1, 0}, {0, 0, -1}, 0.5f);
  auto up = render(s, settings);
  EXPECT_NEAR(estimate(up.image, {"combined.B"}).mean, sky.z, 1e-6);
  EXPECT_NEAR(estimate(up.image, {"emission.G"}).mean, sky.y, 1e-6);
  render::PathTraceSettings pt;
  pt.width = pt.height = 32;
  pt.spp = 4;
  pt.maxDepth = 1;
  pt.camera = atTheOrigin(render::LightSampling::Spatial, 1).camera;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(estimate(pathTrace(s, pt).image, {std::string("combined.") + "RGB"[c]}).mean, 0.5 * sky[c], 1e-4 * sky[c]) << c;
}

TEST_F(DirectLight, FlatLightSelectionKernelsRenderTheGeneralKernelsImage) {
  // The shading kernels leave the light tree and the selection by power out
  // (kSpecConstantFlatLightSelection) exactly where a render can take no other selection: spatial
  // sampling and at most kMaxSpatialLights lights, the frame's spare light slots included.
  EXPECT_TRUE(render::shadingSpecialisation(1, true, gpu::kMaxSpatialLights, {}).flatLightSelection);
  EXPECT_FALSE(render::shadingSpecialisation(1, true, gpu::kMaxSpatialLights + 1, {}).flatLightSelection);
  EXPECT_FALSE(render::shadingSpecialisation(1, false, 3, {}).flatLightSelection);
  // Three lamps over a glossy floor (shadow rays with MIS, specular paths, obscurance): spare
  // light slots past kMaxSpatialLights make the same render use the general kernels, whose
  // dispatches still select among the three lamps spatially. Same estimator, same image.
  SceneBuilder b;
  auto floor = b.glossy(glm::vec3(0.6f, 0.5f, 0.4f), 0.0f, 0.3f);
  auto wall = b.lambertian(glm::vec3(0.3f, 0.6f, 0.3f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  b.quad({-1, 0, -0.5f}, {0, 1, 0}, {2, 0, 0}, wall); // faces +z
  for (int i = 0; i < 3; ++i) {
    auto lamp = b.lambertian(glm::vec3(0.0f), glm::vec3(1.0f + i, 2.0f, 3.0f - i));
    b.quad({-0.9f + 0.6f * i, 0.8f, 0.1f}, {0.3f, 0, 0}, {0, 0, 0.3f}, lamp, "lamp" + std::to_string(i)); // faces -y
  }
  scene::Scene s = b.build();
  render::ObscuranceSettings settings;
  settings.width = settings.height = 24;
  settings.spp = 2;
  settings.camera = lookCamera({0, 0.6f, 1.5f}, {0, -0.3f, -1}, {0, 1, 0}, 1.0f);
  auto flat = render(s, settings);
  settings.spareLightSlots = gpu::kMaxSpatialLights;
  auto general = render(s, settings);
  ASSERT_TRUE(flat.stats.passes.contains("specular"));
  ASSERT_EQ(flat.image.pixels.size(), general.image.pixels.size());
  for (std::size_t i = 0; i < flat.image.pixels.size(); ++i) ASSERT_EQ(flat.image.pixels[i], general.image.pixels[i]) << i;
  EXPECT_GT(estimate(flat.image, {"direct.G"}).mean, 0.0);
}

} // namespace
} // namespace obscura::test
