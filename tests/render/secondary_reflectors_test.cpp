// Important secondary reflectors [RTO §2.2, §6; render/scene_data/secondary_reflectors.h]: the paper's
// hard case, a lamp pointed at a wall. A closed room [0, 2]^3 with a small lamp 0.3 from its
// x = 2 wall, facing it: every other surface is lit only by what that wall reflects.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/one_shot.h"
#include "render/obscurance_renderer.h"
#include "render/scene_data/ambient.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/reached_surfaces.h"
#include "render/scene_data/scene_buffers.h"
#include "render/scene_data/secondary_reflectors.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

// Triangles 2k and 2k + 1 are quad k: floor 0, ceiling 1, wall x = 0 2, wall x = 2 3, z = 0 4,
// z = 2 5, the lamp 6.
constexpr std::uint32_t kDarkWall = 2, kLitWall = 3, kFloor = 0;

constexpr glm::vec3 kBulbPosition{0.5f, 1.5f, 1.2f};

scene::Scene lampAtAWall(bool withBulb = false) {
  SceneBuilder b;
  const auto white = b.lambertian(glm::vec3(0.7f));
  const auto warm = b.lambertian(glm::vec3(0.8f, 0.6f, 0.3f));
  b.quad({0, 0, 0}, {0, 0, 2}, {2, 0, 0}, white); // floor, faces +y
  b.quad({0, 2, 0}, {2, 0, 0}, {0, 0, 2}, white); // ceiling, faces -y
  b.quad({0, 0, 0}, {0, 2, 0}, {0, 0, 2}, white); // x = 0, faces +x
  b.quad({2, 0, 0}, {0, 0, 2}, {0, 2, 0}, warm);  // x = 2, faces -x: the wall the lamp lights
  b.quad({0, 0, 0}, {2, 0, 0}, {0, 2, 0}, white); // z = 0, faces +z
  b.quad({0, 0, 2}, {0, 2, 0}, {2, 0, 0}, white); // z = 2, faces -z
  const auto lamp = b.lambertian(glm::vec3(0.0f), glm::vec3(20.0f));
  b.quad({1.7f, 0.85f, 0.85f}, {0, 0.3f, 0}, {0, 0, 0.3f}, lamp, "lamp"); // faces +x, one-sided
  if (withBulb) b.pointLight(kBulbPosition, glm::vec3(1.0f, 0.9f, 0.8f), 3.0f, "bulb");
  return b.build();
}

render::SecondaryReflectorMarks marks(const scene::Scene& s, double threshold) {
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  std::vector<glm::vec3> albedo;
  for (const auto& m : s.materials) albedo.push_back(render::materialMeanAlbedo(m));
  const render::ReachedSurfaces reached(s, tree, render::triangleReflectances(s, albedo));
  const render::LightSet lights = render::buildLightSet(s);
  std::vector<render::LightReach> reach;
  for (std::size_t l = 0; l < lights.size(); ++l) reach.push_back(reached.measure(lights, l));
  return render::markSecondaryReflectors(s, reach, threshold, reached.totalArea());
}

bool quadMarked(const std::vector<std::uint8_t>& m, std::uint32_t quad) { return m[2 * quad] && m[2 * quad + 1]; }

TEST(SecondaryReflectors, TheWallALampFacesIsMarkedAndTheDarkWallIsNot) {
  const scene::Scene s = lampAtAWall();
  const render::SecondaryReflectorMarks marked = marks(s, 1.0);
  const auto& m = marked.marked;
  EXPECT_EQ(marked.count, 2u);
  // The wall holds most of the lamp's light on a sixth of the room: the rest gets far less than
  // the mean direct irradiance.
  EXPECT_LT(marked.unmarkedFirstBounce, 0.5f);
  EXPECT_GT(marked.unmarkedFirstBounce, 0.0f);
  EXPECT_TRUE(quadMarked(m, kLitWall));
  EXPECT_FALSE(m[2 * kDarkWall] || m[2 * kDarkWall + 1]) << "no light ray reaches the wall behind the lamp";
  EXPECT_FALSE(m[2 * kFloor] || m[2 * kFloor + 1]) << "the floor gets grazing light only, far below the mean";
  // A lower threshold marks what the lamp grazes too; nothing is marked that no ray reached.
  const auto low = marks(s, 1e-6).marked;
  EXPECT_TRUE(low[2 * kFloor] || low[2 * kFloor + 1]);
  EXPECT_FALSE(low[2 * kDarkWall] || low[2 * kDarkWall + 1]);
}

TEST(SecondaryReflectors, AmbientShareBeyondTheFirstBounce) {
  // kappa = 1 - 1 / sum_{j<d} R^(j-1): the whole series keeps R of it, a path of depth 3 (two
  // bounces) 1/3 at R = 0.5, depth 2 (one bounce, the traced one) nothing.
  const glm::vec3 half(0.5f);
  EXPECT_NEAR(render::ambientShareBeyondFirstBounce(half, 0).x, 0.5f, 1e-6f);
  EXPECT_NEAR(render::ambientShareBeyondFirstBounce(half, 3).x, 1.0f / 3.0f, 1e-6f);
  EXPECT_NEAR(render::ambientShareBeyondFirstBounce(half, 6).x, 1.0f - 1.0f / 1.9375f, 1e-6f);
  EXPECT_EQ(render::ambientShareBeyondFirstBounce(half, 2).x, 0.0f);
  EXPECT_EQ(render::ambientShareBeyondFirstBounce(glm::vec3(0.0f), 6).x, 0.0f);
}

class SecondaryReflectorsGpu : public GpuTest {
protected:
  // The camera between the lamp and the dark wall, looking at it: nothing it sees is lit directly.
  static scene::Camera darkSide() {
    return lookCamera({1.5f, 1.0f, 1.0f}, glm::normalize(glm::vec3(-1.0f, -0.1f, 0.05f)), {0, 1, 0}, 1.0f);
  }
  static render::ObscuranceSettings settings(float reflectors, std::uint32_t maxDepth, std::uint32_t seed) {
    render::ObscuranceSettings o;
    o.width = o.height = 24;
    o.spp = 32;
    o.seed = seed;
    o.camera = darkSide();
    o.shadowRays = 2;
    o.obscuranceRays = 8;
    o.maxDepth = maxDepth;
    o.dMax = 2.5f; // from the dark wall, the lit one lies within dmax
    o.secondaryReflectors = reflectors;
    return o;
  }
  static double mean(const io::Image& image, const char* channel) {
    const int c = image.channelIndex(channel);
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int k = 0; k < 3; ++k) sum += image.at(x, y, c + k);
    return sum / (3.0 * image.width * image.height);
  }
  double pathTraced(const scene::Scene& s, const bvh::Bvh& tree, std::uint32_t depth, std::uint32_t seed) {
    render::PathTraceSettings pt;
    pt.width = pt.height = 24;
    pt.spp = 1024;
    pt.seed = seed;
    pt.maxDepth = depth;
    pt.camera = darkSide();
    return mean(renderPathTraced(context(), s, tree, pt).image, "combined.R");
  }
};

// With a dmax that holds the whole room and a threshold that marks each lit triangle, the traced
// reflections in D_s (the `direct` AOV; nothing in view is lit directly) are exactly the
// one-bounce light that path tracing of depth 2 computes: the two means agree within their noise.
// The tolerance, 4 standard errors of the difference, comes from two seeds of each.
TEST_F(SecondaryReflectorsGpu, TracedReflectionsAreThePathTracersOneBounceLight) {
  const scene::Scene s = lampAtAWall();
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  auto obscurance = [&](std::uint32_t seed) {
    render::ObscuranceSettings o = settings(1e-6f, 2, seed);
    o.dMax = 10.0f;
    const ObscuranceResult r = renderObscurances(context(), s, tree, o);
    EXPECT_EQ(r.stats.truncatedTraversals, 0u);
    EXPECT_EQ(mean(r.image, "emission.R"), 0.0); // the lamp is behind the camera
    return mean(r.image, "direct.R");
  };
  const double obs[2] = {obscurance(1), obscurance(2)};
  const double pt[2] = {pathTraced(s, tree, 2, 1), pathTraced(s, tree, 2, 2)};
  // Each mean's standard error from the two seeds: |a - b| / sqrt(2); the difference of the two
  // methods' averages has sqrt(se_obs^2 / 2 + se_pt^2 / 2) (floored at 0.5 % of the mean).
  const double seObs = std::abs(obs[0] - obs[1]) / std::sqrt(2.0), sePt = std::abs(pt[0] - pt[1]) / std::sqrt(2.0);
  const double obsMean = 0.5 * (obs[0] + obs[1]), ptMean = 0.5 * (pt[0] + pt[1]);
  const double tolerance = std::max(4.0 * std::sqrt(0.5 * (seObs * seObs + sePt * sePt)), 0.005 * ptMean);
  std::printf("[ figure   ] dark side, depth 2: obscurance with reflectors %.5f (seeds %.5f, %.5f), path tracing "
              "%.5f (%.5f, %.5f), tolerance %.5f\n",
              obsMean, obs[0], obs[1], ptMean, pt[0], pt[1], tolerance);
  ASSERT_GT(ptMean, 0.0);
  EXPECT_NEAR(obsMean, ptMean, tolerance);
}

// The paper's hard case at full depth: the dark side of the room, lit only by the wall, against
// path tracing. Plain obscurances spread the lamp's flux over every surface it reaches as if the
// room were evenly lit; the traced reflection puts the light where the lit wall sends it. The
// error of the mean falls by at least a third.
TEST_F(SecondaryReflectorsGpu, LampAimedAtAWallIsCloserToPathTracingWithReflectors) {
  const scene::Scene s = lampAtAWall();
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  const double reference = pathTraced(s, tree, 6, 1);
  const ObscuranceResult plain = renderObscurances(context(), s, tree, settings(0.0f, 6, 1));
  const ObscuranceResult traced = renderObscurances(context(), s, tree, settings(1.0f, 6, 1));
  const double plainMean = mean(plain.image, "combined.R"), tracedMean = mean(traced.image, "combined.R");
  std::printf("[ figure   ] dark side, depth 6: path tracing %.5f, obscurances %.5f, with reflectors %.5f\n", reference,
              plainMean, tracedMean);
  EXPECT_LT(std::abs(tracedMean - reference), (2.0 / 3.0) * std::abs(plainMean - reference));
  // The obscurance pass counted the reflectors' shadow rays: there were some, fewer than its rays.
  const std::uint64_t extra = traced.stats.passes.at("shadow").rays - plain.stats.passes.at("shadow").rays;
  EXPECT_GT(extra, 0u);
  EXPECT_LT(extra, traced.stats.passes.at("obscurance").rays);
}

// Adding or removing a light changes what is marked, so both mark anew and retrace every pixel
// with the same seeds: the frame is a fresh render's of the edited scene, bit for bit in its sums.
TEST_F(SecondaryReflectorsGpu, AddedAndRemovedLightsMatchAFreshRenderBitForBit) {
  const scene::Scene s = lampAtAWall(), withBulb = lampAtAWall(true);
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  render::ObscuranceSettings o = settings(1.0f, 6, 5);
  o.spp = 4;
  o.spareLightSlots = 1;
  render::ObscuranceRenderer r(context(), s, tree, o);
  r.render();
  const std::uint32_t marked = r.secondaryReflectors();
  auto expectSame = [&](const scene::Scene& edited, const char* what) {
    r.compose();
    const io::Image relit = r.image();
    const io::Image fresh = renderObscurances(context(), edited, bvh::build(render::triangleSoup(edited)), o).image;
    for (const char* channel : {"direct.R", "direct.B", "indirect.G", "obscurance.Y"}) {
      const int c = fresh.channelIndex(channel);
      std::size_t differ = 0;
      for (int y = 0; y < fresh.height; ++y)
        for (int x = 0; x < fresh.width; ++x) differ += fresh.at(x, y, c) != relit.at(x, y, c);
      EXPECT_EQ(differ, 0u) << what << ", " << channel;
    }
  };
  scene::PunctualLight bulb;
  bulb.name = "bulb";
  bulb.type = scene::PunctualType::Point;
  bulb.position = kBulbPosition;
  bulb.color = glm::vec3(1.0f, 0.9f, 0.8f);
  bulb.intensity = 3.0f;
  r.addLight(bulb);
  EXPECT_GT(r.secondaryReflectors(), marked) << "the bulb lights the room's near surfaces more than their mean";
  expectSame(withBulb, "bulb added");
  r.removeLight(r.lightIndex("bulb"));
  EXPECT_EQ(r.secondaryReflectors(), marked);
  expectSame(s, "bulb removed");
}

// Off by default, and a threshold that marks nothing renders the same bits as off.
TEST_F(SecondaryReflectorsGpu, NothingMarkedRendersTheSameBitsAsOff) {
  const scene::Scene s = lampAtAWall();
  const bvh::Bvh tree = bvh::build(render::triangleSoup(s));
  EXPECT_EQ(render::ObscuranceSettings{}.secondaryReflectors, 0.0f);
  const io::Image off = renderObscurances(context(), s, tree, settings(0.0f, 6, 3)).image;
  const io::Image none = renderObscurances(context(), s, tree, settings(1e9f, 6, 3)).image;
  ASSERT_EQ(off.pixels.size(), none.pixels.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < off.pixels.size(); ++i) differ += off.pixels[i] != none.pixels[i];
  EXPECT_EQ(differ, 0u);
}

} // namespace
} // namespace obscura::test
