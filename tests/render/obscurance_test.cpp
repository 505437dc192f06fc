// Ray-traced obscurances against analytic answers [RTO; SPEC §1]: obscurance of an open plane
// and of a floor under an infinite parallel ceiling (every rho, both sampling modes, with colour
// bleeding), direct light from a point light and from a square area light, determinism, and
// the passes a scene does not need are not dispatched.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "render/one_shot.h"
#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/obscurance_renderer.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kHalfSize = 1000.0f; // "infinite" planes: far larger than dMax

class Obscurance : public GpuTest {
protected:
  test::ObscuranceResult render(const scene::Scene& s, render::ObscuranceSettings settings) {
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    auto result = test::renderObscurances(context(), s, tree, settings);
    EXPECT_EQ(result.stats.truncatedTraversals, 0u);
    for (float v : result.image.pixels) EXPECT_TRUE(std::isfinite(v));
    return result;
  }
  // Mean of one channel over the pixels that hit something.
  static double mean(const io::Image& image, const std::string& channel) {
    int c = image.channelIndex(channel), coverage = image.channelIndex("coverage.A");
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        if (image.at(x, y, coverage) == 1.0f) {
          sum += image.at(x, y, c);
          ++n;
        }
    EXPECT_GT(n, 0);
    return n ? sum / n : 0.0;
  }
};

scene::Scene floorScene(glm::vec3 albedo = glm::vec3(0.5f)) {
  SceneBuilder b;
  auto m = b.lambertian(albedo);
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, m); // faces +y
  return b.build();
}

// Floor at y = 0 and a ceiling at y = h facing it.
scene::Scene slabScene(float h, glm::vec3 ceilingAlbedo, glm::vec3 floorAlbedo = glm::vec3(0.5f)) {
  SceneBuilder b;
  auto floor = b.lambertian(floorAlbedo);
  auto ceiling = b.lambertian(ceilingAlbedo);
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  b.quad({-kHalfSize, h, -kHalfSize}, {2 * kHalfSize, 0, 0}, {0, 0, 2 * kHalfSize}, ceiling);
  // A faint point light far away, so that I_a > 0 and the indirect AOV carries W_c.
  b.pointLight({0, 0.5f * h, 0}, glm::vec3(1.0f), 1.0f);
  return b.build();
}

render::ObscuranceSettings lookDown(float height, float yfov, std::uint32_t size, std::uint32_t spp) {
  render::ObscuranceSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.camera = lookCamera({0, height, 0}, {0, -1, 0}, {0, 0, -1}, yfov);
  return s;
}

TEST_F(Obscurance, OpenPlaneIsFullyOpenForEveryRhoAndSampling) {
  scene::Scene s = floorScene();
  for (auto rho : {render::RhoKind::Sqrt, render::RhoKind::Exp, render::RhoKind::Ao})
    for (bool systematic : {true, false}) {
      auto settings = lookDown(1.0f, 1.0f, 16, 2);
      settings.rho = rho;
      settings.systematic = systematic;
      settings.obscuranceRays = 8;
      auto r = render(s, settings);
      int c = r.image.channelIndex("obscurance.Y");
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) ASSERT_EQ(r.image.at(x, y, c), 1.0f) << x << "," << y;
    }
}

struct SlabCase {
  render::RhoKind rho;
  bool systematic;
};

TEST_F(Obscurance, FloorUnderParallelCeilingMatchesTheClosedForm) {
  const float h = 1.0f, dMax = 2.0f, k = h / dMax;
  const glm::vec3 ceilingAlbedo(0.2f, 0.5f, 0.8f);
  scene::Scene s = slabScene(h, ceilingAlbedo);
  // AO: rho = 0 wherever the ceiling is within dMax (cos theta > k), so W = k^2.
  // sqrt: W = 2 int_0^1 rho(d) c dc with d = h/c: (4/3) sqrt(k) - k^2 / 3.
  const double wAo = k * k, wSqrt = 4.0 / 3.0 * std::sqrt(k) - k * k / 3.0;
  for (SlabCase c : {SlabCase{render::RhoKind::Ao, true}, SlabCase{render::RhoKind::Ao, false},
                     SlabCase{render::RhoKind::Sqrt, true}, SlabCase{render::RhoKind::Sqrt, false}}) {
    // Two budgets: the tolerance (4 sigma of a mean of values in [0, 1]) shrinks with samples.
    for (std::uint32_t spp : {1u, 8u}) {
      auto settings = lookDown(0.5f * h, 0.3f, 32, spp);
      settings.rho = c.rho;
      settings.systematic = c.systematic;
      settings.obscuranceRays = 16;
      settings.dMax = dMax;
      auto r = render(s, settings);
      const double n = 32.0 * 32.0 * spp * settings.obscuranceRays;
      const double tolerance = 4.0 * 0.5 / std::sqrt(n);
      const double expectedW = c.rho == render::RhoKind::Ao ? wAo : wSqrt;
      EXPECT_NEAR(mean(r.image, "obscurance.Y"), expectedW, tolerance)
          << "rho " << int(c.rho) << (c.systematic ? " systematic" : " random") << " spp " << spp;
      // Colour bleeding: W_c = a (hit part) + R_ave (miss part) [RTO eq. 6, SPEC §1.2]; the
      // indirect AOV is I_a R(P) W_c with R(P) the floor's albedo 0.5.
      const glm::vec3 rAve = r.ambient.averageReflectance;
      for (int ch = 0; ch < 3; ++ch) {
        double hitPart = c.rho == render::RhoKind::Ao ? 0.0 : wSqrt - wAo;
        double expectedWc = ceilingAlbedo[ch] * hitPart + rAve[ch] * wAo;
        double indirect = mean(r.image, std::string("indirect.") + "RGB"[ch]);
        double wc = indirect / (r.ambientIntensity[ch] * 0.5);
        EXPECT_NEAR(wc, expectedWc, tolerance) << "channel " << ch;
      }
    }
  }
}

TEST_F(Obscurance, GreyObscuranceTracesTheSameRaysAndLeavesTheColourOut) {
  // Without colour bleeding the pass runs its grey variant (kSpecConstantGreyObscurance), which
  // never looks up the surface an obscurance ray hits. Same seed, same rays: W is the same, pixel
  // for pixel, as with bleeding, and the indirect AOV is I_a R(P) W in every channel (R(P) = 0.5,
  // the floor), whatever the ceiling's colour.
  const float h = 1.0f, dMax = 2.0f;
  scene::Scene s = slabScene(h, glm::vec3(0.2f, 0.5f, 0.8f));
  auto settings = lookDown(0.5f * h, 0.3f, 16, 2);
  settings.obscuranceRays = 8;
  settings.dMax = dMax;
  auto bleeding = render(s, settings);
  settings.colourBleeding = false;
  auto grey = render(s, settings);
  const int w = grey.image.channelIndex("obscurance.Y");
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      ASSERT_EQ(grey.image.at(x, y, w), bleeding.image.at(x, y, w)) << x << "," << y;
      for (int ch = 0; ch < 3; ++ch) {
        const float expected = grey.ambientIntensity[ch] * 0.5f * grey.image.at(x, y, w);
        ASSERT_NEAR(grey.image.at(x, y, grey.image.channelIndex(std::string("indirect.") + "RGB"[ch])), expected,
                    1e-5f * expected + 1e-7f)
            << x << "," << y << " channel " << ch;
      }
    }
}

// Dark escapes (EscapeModel): an obscurance ray that misses within dMax is traced on; if it leaves
// the scene it brings no ambient light, if it meets a surface past dMax it keeps the paper's R_ave.
TEST_F(Obscurance, ARayThatLeavesTheSceneBringsNoAmbientLight) {
  SceneBuilder b;
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, b.lambertian(glm::vec3(0.5f)));
  b.pointLight({0, 2, 0}, glm::vec3(1.0f), 5.0f); // I_a > 0
  const scene::Scene s = b.build();
  auto settings = lookDown(1.0f, 1.0f, 16, 2);
  settings.obscuranceRays = 8;
  settings.escapes = render::EscapeModel::Dark;
  const auto dark = render(s, settings);
  settings.escapes = render::EscapeModel::Ambient;
  const auto ambient = render(s, settings);
  const int w = dark.image.channelIndex("obscurance.Y");
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      ASSERT_EQ(dark.image.at(x, y, w), 1.0f) << "W keeps the paper's openness within dMax";
      for (int ch = 0; ch < 3; ++ch) {
        const std::string indirect = std::string("indirect.") + "RGB"[ch];
        ASSERT_EQ(dark.image.at(x, y, dark.image.channelIndex(indirect)), 0.0f) << x << "," << y;
        // The paper's: W_c = R_ave on a miss, so the indirect light is R(P) R_ave I_a.
        const float expected = 0.5f * ambient.ambient.averageReflectance[ch] * ambient.ambientIntensity[ch];
        ASSERT_GT(expected, 0.0f);
        ASSERT_NEAR(ambient.image.at(x, y, ambient.image.channelIndex(indirect)), expected, 1e-5f * expected);
      }
    }
}

TEST_F(Obscurance, ARayPastDmaxThatMeetsASurfaceKeepsTheAmbientAndAutoFollowsTheScene) {
  // Floor under a parallel ceiling 1 above, dMax 0.5: every obscurance ray misses within dMax and
  // meets the ceiling past it, so dark escapes change nothing (R_ave I_a on every ray), and they
  // cost one more ray per miss. (A ray can leave only below 0.06 degrees over the horizon, on the
  // 1000-wide quads: the means are compared, not the pixels.)
  const scene::Scene slab = slabScene(1.0f, glm::vec3(0.2f, 0.5f, 0.8f));
  auto settings = lookDown(0.5f, 0.3f, 16, 4);
  settings.obscuranceRays = 8;
  settings.dMax = 0.5f;
  settings.escapes = render::EscapeModel::Dark;
  const auto dark = render(slab, settings);
  settings.escapes = render::EscapeModel::Ambient;
  const auto ambient = render(slab, settings);
  for (const char* channel : {"indirect.R", "indirect.G", "indirect.B"}) {
    const double expected = mean(ambient.image, channel);
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(mean(dark.image, channel), expected, 1e-4 * expected) << channel;
  }
  EXPECT_EQ(dark.stats.passes.at("obscurance").rays, 2 * ambient.stats.passes.at("obscurance").rays);

  // Auto: dark where rays from the camera's surfaces leave the scene (the slab's sides, 1000 away,
  // do not count: none of the free-path rays gets there), ambient in a closed box.
  const auto resolved = [&](const scene::Scene& scene, const scene::Camera& camera) {
    render::ObscuranceSettings s;
    s.width = s.height = 8;
    s.camera = camera;
    s.ambient = render::AmbientModel::Global;
    const bvh::Bvh tree = bvh::build(render::triangleSoup(scene));
    return render::ObscuranceRenderer(context(), scene, tree, s).darkEscapes();
  };
  SceneBuilder box;
  const auto white = box.lambertian(glm::vec3(0.5f));
  box.quad({-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, white); // floor, +y
  box.quad({-1, 2, -1}, {2, 0, 0}, {0, 0, 2}, white); // ceiling, -y
  box.quad({-1, 0, -1}, {0, 2, 0}, {0, 0, 2}, white); // left, +x
  box.quad({1, 0, -1}, {0, 0, 2}, {0, 2, 0}, white);  // right, -x
  box.quad({-1, 0, -1}, {2, 0, 0}, {0, 2, 0}, white); // back, +z
  const scene::Scene open = box.build();               // no front wall
  box.quad({-1, 0, 1}, {0, 2, 0}, {2, 0, 0}, white);  // front, -z
  const scene::Scene closed = box.build();
  const scene::Camera inside = lookCamera({0, 1, 0.9f}, {0, 0, -1}, {0, 1, 0}, 1.2f);
  EXPECT_TRUE(resolved(open, inside));
  EXPECT_FALSE(resolved(closed, inside));
  EXPECT_FALSE(resolved(slab, lookDown(0.5f, 0.3f, 8, 1).camera));
}

TEST_F(Obscurance, PointLightOverAPlaneIsExact) {
  SceneBuilder b;
  auto floor = b.lambertian(glm::vec3(0.5f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  const glm::vec3 light(0.3f, 2.0f, -0.2f);
  const float intensity = 10.0f;
  b.pointLight(light, glm::vec3(1.0f), intensity);
  scene::Scene s = b.build();
  auto settings = lookDown(1.0f, 1.2f, 24, 1); // one sample: the position AOV is that sample's
  settings.shadowRays = 1;
  settings.obscuranceRays = 0;
  auto r = render(s, settings);
  int direct = r.image.channelIndex("direct.R"), position = r.image.channelIndex("position.X");
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      glm::vec3 p(r.image.at(x, y, position), r.image.at(x, y, position + 1), r.image.at(x, y, position + 2));
      glm::vec3 d = light - p;
      float r2 = glm::dot(d, d);
      float expected = 0.5f / kPi * intensity * (d.y / std::sqrt(r2)) / r2; // f E cos / r^2
      EXPECT_NEAR(r.image.at(x, y, direct), expected, 1e-4f * expected) << x << "," << y;
    }
}

TEST_F(Obscurance, SquareAreaLightMatchesTheFormFactor) {
  // A square emitter of half-side a at height h, centred over the origin and facing down, with
  // unit radiance: irradiance at the origin E = pi L F with the differential-area-to-parallel-
  // square form factor F = (4/pi) X/sqrt(1+X^2) atan(X/sqrt(1+X^2)), X = a/h (four corner
  // rectangles); the floor's radiance is albedo * L * F.
  const float a = 0.5f, h = 1.0f, albedo = 0.5f;
  SceneBuilder b;
  auto floor = b.lambertian(glm::vec3(albedo));
  auto emitter = b.lambertian(glm::vec3(0.0f), glm::vec3(1.0f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floor);
  b.quad({-a, h, -a}, {2 * a, 0, 0}, {0, 0, 2 * a}, emitter, "square"); // faces -y
  scene::Scene s = b.build();
  auto settings = lookDown(0.5f, 0.002f, 16, 16); // every pixel within 1e-3 of the origin
  settings.shadowRays = 16;
  settings.obscuranceRays = 0;
  auto r = render(s, settings);
  const double x = a / h, q = x / std::sqrt(1.0 + x * x);
  const double formFactor = 4.0 / std::numbers::pi * q * std::atan(q);
  EXPECT_NEAR(mean(r.image, "direct.G"), albedo * formFactor, 0.01 * albedo * formFactor);
}

TEST_F(Obscurance, MirrorReflectsAnEmitterExactly) {
  // A perfect mirror floor (metallic 1, roughness 0, white: F = 1) under an emitter of radiance
  // (2, 1, 0.5) facing it: the camera sees the emitter through one delta bounce, so the specular
  // AOV, and the whole image, is that radiance. The mirror has no diffuse part, so neither
  // shadow rays nor obscurance add anything at the primary hit.
  SceneBuilder b;
  auto mirror = b.glossy(glm::vec3(1.0f), 1.0f, 0.0f);
  auto emitter = b.lambertian(glm::vec3(0.0f), glm::vec3(2.0f, 1.0f, 0.5f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, mirror);
  b.quad({-kHalfSize, 2, -kHalfSize}, {2 * kHalfSize, 0, 0}, {0, 0, 2 * kHalfSize}, emitter, "sky"); // faces -y
  scene::Scene s = b.build();
  auto settings = lookDown(1.0f, 0.8f, 16, 2);
  auto r = render(s, settings);
  ASSERT_TRUE(r.stats.passes.contains("specular"));
  for (const char* channel : {"specular.R", "combined.R"})
    EXPECT_NEAR(mean(r.image, channel), 2.0, 1e-4) << channel;
  EXPECT_NEAR(mean(r.image, "specular.G"), 1.0, 1e-4);
  EXPECT_NEAR(mean(r.image, "specular.B"), 0.5, 1e-4);
  EXPECT_NEAR(mean(r.image, "direct.R"), 0.0, 1e-6);
  EXPECT_NEAR(mean(r.image, "indirect.R"), 0.0, 1e-6);
}

TEST_F(Obscurance, FacingMirrorsReflectAnEmittingMirrorOncePerRoundTripUpToTheMaximumDepth) {
  // A white mirror floor (F = 1) under an emitting mirror ceiling of reflectance c = 0.5 (metallic,
  // base colour c: F = c at the near-normal incidence of a 0.2 rad field of view, the Schlick term
  // (1 - cos)^5 < 1e-11) and radiance 1. A path from the floor meets the ceiling at depths 1, 3,
  // 5, ... with throughputs 1, c, c^2, ... and sees its emission each time (whole: delta bounces),
  // so with paths of maxDepth scattering vertices the image is sum_{k < maxDepth / 2} c^k. Neither
  // mirror has a diffuse part, so no shadow ray or obscurance adds anything. The specular pass
  // runs one dispatch per depth: a depth that is not run, or a path not carried to the next,
  // changes the sum.
  const float c = 0.5f;
  SceneBuilder b;
  auto floorMirror = b.glossy(glm::vec3(1.0f), 1.0f, 0.0f);
  auto ceiling = b.glossy(glm::vec3(c), 1.0f, 0.0f, glm::vec3(1.0f));
  b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floorMirror);
  b.quad({-kHalfSize, 2, -kHalfSize}, {2 * kHalfSize, 0, 0}, {0, 0, 2 * kHalfSize}, ceiling, "ceiling"); // faces -y
  scene::Scene s = b.build();
  for (std::uint32_t maxDepth : {1u, 2u, 3u, 4u, 6u}) {
    auto settings = lookDown(1.0f, 0.2f, 8, 1);
    settings.maxDepth = maxDepth;
    auto r = render(s, settings);
    double expected = 0.0;
    for (std::uint32_t depth = 1; depth < maxDepth; depth += 2) expected += std::pow(c, (depth - 1) / 2);
    const int channel = r.image.channelIndex("combined.R");
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x)
        ASSERT_NEAR(r.image.at(x, y, channel), expected, 1e-4) << "maxDepth " << maxDepth << " at " << x << "," << y;
  }
}

TEST_F(Obscurance, AMetalPathVertexTracesNoObscuranceRays) {
  // A white mirror floor under a ceiling at height 2: the camera's paths meet the ceiling at their
  // first vertex (depth 2 is the last). A metal ceiling reflects none of the ambient (R(P) = 0), so
  // its vertices trace the same rays with 5 obscurance rays per hit as with none; a Lambertian
  // one traces 5 more at each. A lamp beside them gives the shadow rays a light.
  for (bool metalCeiling : {true, false}) {
    SCOPED_TRACE(metalCeiling ? "metal ceiling" : "Lambertian ceiling");
    SceneBuilder b;
    auto floorMirror = b.glossy(glm::vec3(1.0f), 1.0f, 0.0f);
    auto ceiling = metalCeiling ? b.glossy(glm::vec3(0.5f), 1.0f, 0.3f) : b.lambertian(glm::vec3(0.5f));
    auto lamp = b.lambertian(glm::vec3(0.0f), glm::vec3(1.0f));
    b.quad({-kHalfSize, 0, -kHalfSize}, {0, 0, 2 * kHalfSize}, {2 * kHalfSize, 0, 0}, floorMirror);
    b.quad({-kHalfSize, 2, -kHalfSize}, {2 * kHalfSize, 0, 0}, {0, 0, 2 * kHalfSize}, ceiling); // faces -y
    b.quad({-0.1f, 1.5f, 3.0f}, {0.2f, 0, 0}, {0, 0.2f, 0}, lamp, "lamp");
    scene::Scene s = b.build();
    std::uint64_t specularRays[2] = {0, 0};
    for (std::uint32_t obscuranceRays : {0u, 5u}) {
      auto settings = lookDown(1.0f, 0.2f, 8, 1);
      settings.maxDepth = 2;
      settings.obscuranceRays = obscuranceRays;
      auto r = render(s, settings);
      ASSERT_TRUE(r.stats.passes.contains("specular"));
      specularRays[obscuranceRays ? 1 : 0] = r.stats.passes.at("specular").rays;
    }
    EXPECT_GT(specularRays[0], 0u);
    if (metalCeiling) EXPECT_EQ(specularRays[1], specularRays[0]);
    else EXPECT_EQ(specularRays[1], specularRays[0] + 5u * 64u) << "one path a pixel, 64 pixels";
  }
}

TEST_F(Obscurance, SameSeedSameImageNoNaNAndOnlyNeededPasses) {
  scene::Scene s = scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"));
  render::ObscuranceSettings settings;
  settings.width = settings.height = 24;
  settings.spp = 2;
  settings.camera = s.cameras.at(0);
  auto a = render(s, settings), b2 = render(s, settings);
  ASSERT_EQ(a.image.pixels.size(), b2.image.pixels.size());
  for (std::size_t i = 0; i < a.image.pixels.size(); ++i) ASSERT_EQ(a.image.pixels[i], b2.image.pixels[i]) << i;
  EXPECT_TRUE(a.stats.passes.contains("shadow"));
  EXPECT_FALSE(a.stats.passes.contains("specular")); // the Cornell box is all Lambertian
  EXPECT_GT(a.stats.passes.at("shadow").rays, 0u);
  // A scene without lights: no shadow pass at all, and obscurance still renders.
  scene::Scene dark = floorScene();
  auto d = render(dark, lookDown(1.0f, 1.0f, 8, 1));
  EXPECT_FALSE(d.stats.passes.contains("shadow"));
  EXPECT_TRUE(d.stats.passes.contains("obscurance"));
}

} // namespace
} // namespace obscura::test
