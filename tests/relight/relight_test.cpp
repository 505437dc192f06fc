// Relighting [IVR; SPEC §3]: a light edit recomposes the kept per-light transport with no ray,
// an added light traces only its own shadow rays, and every edited frame is statistically the
// frame a fresh render of the scene edited the same way gives.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/incremental_refit.h"
#include "bvh/insert.h"
#include "gpu_test.h"
#include "render/obscurance_renderer.h"
#include "render/one_shot.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "render/transport.h"
#include "scene/scene_edit.h"

namespace obscura::test {
namespace {

// A room: white floor, red back wall, white side wall, two ceiling lamps (light groups lampA,
// lampB) and a point light "bulb". What the edits change is passed in.
struct RoomLights {
  glm::vec3 lampA{3.0f}, lampB{2.0f, 2.0f, 1.5f};
  float bulb = 2.0f;
  bool withBulb = true;
  bool withAdded = false; // a second point light, "added"
  bool withPanel = false; // an emissive quad, "panel" (kPanel), the last light group
  bool glossyFloor = false; // a rough metal floor: specular paths from every floor pixel
};

constexpr glm::vec3 kAddedPosition{0.6f, 0.5f, 0.6f};
constexpr float kAddedIntensity = 1.5f;
// A warm panel standing right of the screen, facing the left wall (-x), seen obliquely.
const scene::EmissiveQuad kPanel{.name = "panel", .corner = {0.8f, 0.2f, 0.1f}, .edge1 = {0.0f, 0.6f, 0.0f},
                                 .edge2 = {0.0f, 0.0f, -0.6f}, .emission = {8.0f, 7.0f, 6.0f}};

// The point light "added", as a scene with withAdded has it.
scene::PunctualLight addedLight() {
  scene::PunctualLight added;
  added.name = "added";
  added.type = scene::PunctualType::Point;
  added.position = kAddedPosition;
  added.color = glm::vec3(0.7f, 0.8f, 1.0f);
  added.intensity = kAddedIntensity;
  return added;
}

scene::Scene room(const RoomLights& l) {
  SceneBuilder b;
  auto white = b.lambertian(glm::vec3(0.7f));
  auto red = b.lambertian(glm::vec3(0.7f, 0.15f, 0.1f));
  auto lampA = b.lambertian(glm::vec3(0.0f), l.lampA);
  auto lampB = b.lambertian(glm::vec3(0.0f), l.lampB);
  b.quad({-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, l.glossyFloor ? b.glossy(glm::vec3(0.8f), 1.0f, 0.2f) : white); // floor, +y
  b.quad({-1, 0, -1}, {2, 0, 0}, {0, 2, 0}, red);         // back wall, faces +z
  b.quad({-1, 0, -1}, {0, 2, 0}, {0, 0, 2}, white);       // left wall, faces +x
  b.quad({-1, 2, -1}, {2, 0, 0}, {0, 0, 2}, white);       // ceiling, faces -y
  b.quad({-0.6f, 1.99f, -0.6f}, {0.4f, 0, 0}, {0, 0, 0.4f}, lampA, "lampA");
  b.quad({0.3f, 1.99f, 0.1f}, {0.3f, 0, 0}, {0, 0, 0.3f}, lampB, "lampB");
  b.quad({-0.2f, 0.0f, -0.2f}, {0.4f, 0, 0}, {0, 0.6f, 0}, white); // a screen casting shadows
  if (l.withPanel) b.quad(kPanel.corner, kPanel.edge1, kPanel.edge2, b.lambertian(glm::vec3(0.0f), kPanel.emission), "panel");
  if (l.withBulb) b.pointLight({-0.5f, 1.2f, 0.5f}, glm::vec3(1.0f, 0.9f, 0.7f), l.bulb, "bulb");
  if (l.withAdded) b.pointLight(addedLight().position, addedLight().color, addedLight().intensity, "added");
  return b.build();
}

render::ObscuranceSettings roomSettings(std::uint32_t seed) {
  render::ObscuranceSettings s;
  s.width = 48;
  s.height = 36;
  s.spp = 32;
  s.seed = seed;
  s.shadowRays = 4;
  s.obscuranceRays = 4;
  s.camera = lookCamera({0.2f, 1.0f, 3.2f}, glm::normalize(glm::vec3(-0.1f, -0.05f, -1.0f)), {0, 1, 0}, 0.9f);
  s.spareLightSlots = 1; // the added-light tests
  s.keptRaySamples = s.spp; // as relight --edits: an added light follows the kept lobe hits
  return s;
}

std::vector<float> channel(const io::Image& image, const std::string& name) {
  const int c = image.channelIndex(name);
  EXPECT_GE(c, 0) << name;
  std::vector<float> out;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) out.push_back(image.at(x, y, c));
  return out;
}

// Luminance means of 6x6 pixel blocks of `combined`.
std::vector<double> blockMeans(const io::Image& image) {
  std::vector<double> means;
  const int r = image.channelIndex("combined.R");
  for (int by = 0; by + 6 <= image.height; by += 6)
    for (int bx = 0; bx + 6 <= image.width; bx += 6) {
      double sum = 0.0;
      for (int y = by; y < by + 6; ++y)
        for (int x = bx; x < bx + 6; ++x)
          for (int c = 0; c < 3; ++c) sum += image.at(x, y, r + c);
      means.push_back(sum / 108.0);
    }
  return means;
}

double rmsDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum / static_cast<double>(a.size()));
}

class Relight : public GpuTest {
protected:
  render::ObscuranceRenderer& base(const RoomLights& lights = {}) {
    if (!renderer_) {
      scene_ = room(lights);
      bvh_ = bvh::build(render::triangleSoup(scene_));
      renderer_ = std::make_unique<render::ObscuranceRenderer>(context(), scene_, bvh_, roomSettings(7));
      renderer_->render();
      EXPECT_EQ(renderer_->stats().truncatedTraversals, 0u);
    }
    return *renderer_;
  }
  // A fresh render of the room with these lights.
  io::Image fresh(const RoomLights& lights, std::uint32_t seed) {
    scene::Scene s = room(lights);
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    return renderObscurances(context(), s, tree, roomSettings(seed)).image;
  }
  // The contract: an edited frame is the fresh render of the edited scene up to noise. The
  // tolerance comes from the same render's seed-to-seed spread: two fresh renders (seeds 11 and
  // 12) differ in block means by an RMS of `spread`; the relit frame must be within 3 spread of
  // a fresh one in RMS (a missing or doubled term, e.g. I_a not following the edit or the seen
  // emission not dimmed, moves many blocks by far more).
  void expectStatisticallyEqual(const io::Image& relit, const RoomLights& edited) {
    const auto a = blockMeans(fresh(edited, 11)), b = blockMeans(fresh(edited, 12));
    const double spread = rmsDifference(a, b);
    const double error = rmsDifference(blockMeans(relit), a);
    ASSERT_GT(spread, 0.0);
    EXPECT_LT(error, 3.0 * spread) << "relit vs fresh RMS " << error << ", seed-to-seed RMS " << spread;
  }
  std::size_t light(const std::string& name) { return base().lightIndex(name); }

  scene::Scene scene_;
  bvh::Bvh bvh_;
  scene::Scene edited_; // a geometry edit's scene, which the renderer points to
  bvh::Bvh editedBvh_;
  std::unique_ptr<render::ObscuranceRenderer> renderer_;
};

TEST_F(Relight, IdentityEditGivesTheBitIdenticalFrame) {
  auto& r = base();
  const io::Image before = r.image();
  r.setEmissions(r.emissions());
  r.compose();
  const io::Image after = r.image();
  ASSERT_EQ(before.pixels.size(), after.pixels.size());
  EXPECT_EQ(std::memcmp(before.pixels.data(), after.pixels.data(), before.pixels.size() * 4), 0);
}

TEST_F(Relight, ScalingEveryLightByKScalesTheFrameByK) {
  auto& r = base();
  const auto before = channel(r.image(), "combined.G");
  std::vector<glm::vec3> scaled;
  for (const auto& e : r.emissions()) scaled.push_back(e * 2.5f);
  r.setEmissions(scaled);
  r.compose();
  const auto after = channel(r.image(), "combined.G");
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_NEAR(after[i], 2.5f * before[i], 1e-6f * std::max(1.0f, 2.5f * before[i])) << "pixel " << i;
}

TEST_F(Relight, LightLayersSumToCombined) {
  auto& r = base();
  std::vector<glm::vec3> e = r.emissions();
  e[light("lampA")] *= glm::vec3(0.5f, 1.0f, 2.0f);
  r.setEmissions(e);
  r.compose();
  const io::Image image = r.image(), layers = r.lightLayers();
  ASSERT_EQ(layers.channels.size(), 3 * r.lights().size());
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        float sum = 0.0f;
        for (std::size_t s = 0; s < r.lights().size(); ++s) sum += layers.at(x, y, static_cast<int>(s * 3 + c));
        const float combined = image.at(x, y, image.channelIndex("combined.R") + c);
        EXPECT_NEAR(sum, combined, 1e-5f * std::max(1.0f, combined)) << x << "," << y;
      }
}

TEST_F(Relight, HostComposeTwinMatchesTheGpuCompose) {
  auto& r = base();
  std::vector<glm::vec3> e = r.emissions();
  e[light("bulb")] *= 3.0f;
  e[light("lampB")] = glm::vec3(0.5f, 4.0f, 0.0f);
  r.setEmissions(e);
  r.compose();
  const io::Image gpu = r.image();
  const io::Image host = render::composeTransport(r.transport(), e, r.ambient().weight);
  for (const char* channelName : {"combined.R", "combined.B", "direct.G", "indirect.R", "emission.G", "obscurance.Y"}) {
    const auto a = channel(gpu, channelName), b = channel(host, channelName);
    for (std::size_t i = 0; i < a.size(); ++i)
      EXPECT_NEAR(a[i], b[i], 1e-5f * std::max(1.0f, std::abs(a[i]))) << channelName << " pixel " << i;
  }
}

TEST_F(Relight, DimmingALampTheCameraSeesDimsItsImage) {
  auto& r = base();
  // The room's lamps face down, so look at them from below: the seen emission M_s is per light.
  std::vector<glm::vec3> e = r.emissions();
  const auto before = channel(r.image(), "emission.R");
  e[light("lampA")] *= 0.25f;
  e[light("lampB")] = glm::vec3(0.0f);
  r.setEmissions(e);
  r.compose();
  const auto after = channel(r.image(), "emission.R");
  // Each seen-emission pixel belongs to one lamp: it is either a quarter (lampA) or 0 (lampB).
  int seen = 0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (before[i] == 0.0f) continue;
    ++seen;
    const bool quarter = std::abs(after[i] - 0.25f * before[i]) <= 1e-6f * before[i];
    EXPECT_TRUE(quarter || after[i] == 0.0f) << "pixel " << i << ": " << before[i] << " -> " << after[i];
  }
  EXPECT_GT(seen, 0) << "the camera must see a lamp for this test";
}

TEST_F(Relight, ScaledLampMatchesAFreshRenderOfTheEditedScene) {
  auto& r = base();
  std::vector<glm::vec3> e = r.emissions();
  e[light("lampA")] *= 3.0f;
  r.setEmissions(e);
  r.compose();
  RoomLights edited;
  edited.lampA *= 3.0f;
  expectStatisticallyEqual(r.image(), edited);
}

TEST_F(Relight, RecolouredLampMatchesAFreshRenderOfTheEditedScene) {
  auto& r = base();
  std::vector<glm::vec3> e = r.emissions();
  e[light("lampB")] *= glm::vec3(1.0f, 0.2f, 0.2f);
  r.setEmissions(e);
  r.compose();
  RoomLights edited;
  edited.lampB *= glm::vec3(1.0f, 0.2f, 0.2f);
  expectStatisticallyEqual(r.image(), edited);
}

TEST_F(Relight, SwitchedOffBulbMatchesAFreshRenderWithoutIt) {
  auto& r = base();
  std::vector<glm::vec3> e = r.emissions();
  e[light("bulb")] = glm::vec3(0.0f);
  r.setEmissions(e);
  r.compose();
  RoomLights edited;
  edited.withBulb = false;
  expectStatisticallyEqual(r.image(), edited);
}

TEST_F(Relight, RemovedBulbMatchesAFreshRenderWithoutIt) {
  auto& r = base();
  r.removeLight(light("bulb"));
  EXPECT_EQ(r.lights().size(), 2u);
  r.compose();
  RoomLights edited;
  edited.withBulb = false;
  expectStatisticallyEqual(r.image(), edited);
}

TEST_F(Relight, AddedLightTracesOnlyItsShadowRaysAndMatchesAFreshRender) {
  auto& r = base();
  const render::RenderStats before = r.stats();
  r.addLight(addedLight());
  r.compose();
  const render::RenderStats after = r.stats();
  // No obscurance ray; one shadow ray for the new point light (exact) at every hit pixel of every
  // sample.
  EXPECT_EQ(after.passes.at("obscurance").rays, before.passes.at("obscurance").rays);
  const std::uint64_t shadowRays = after.passes.at("shadow").rays - before.passes.at("shadow").rays;
  const auto coverage = channel(r.image(), "coverage.A");
  double hits = 0.0;
  for (float c : coverage) hits += c;
  EXPECT_NEAR(static_cast<double>(shadowRays), hits * 32, 32 * 2.0); // coverage is a mean over samples
  RoomLights edited;
  edited.withAdded = true;
  expectStatisticallyEqual(r.image(), edited);
}

// An added light reaches what the camera sees through a glossy floor: its rays are traced along
// the frame's own specular paths too (followed again, gathering that light alone).
TEST_F(Relight, AddedLightIsGatheredAlongTheSpecularPathsOfAGlossyFloor) {
  RoomLights glossy;
  glossy.glossyFloor = true;
  auto& r = base(glossy);
  ASSERT_TRUE(r.specular());
  const render::RenderStats before = r.stats();
  r.addLight(addedLight());
  r.compose();
  const render::RenderStats after = r.stats();
  EXPECT_GT(after.passes.at("specular").rays, before.passes.at("specular").rays);
  EXPECT_EQ(after.passes.at("obscurance").rays, before.passes.at("obscurance").rays);
  EXPECT_EQ(after.truncatedTraversals, 0u);
  RoomLights edited = glossy;
  edited.withAdded = true;
  expectStatisticallyEqual(r.image(), edited);
}

// The kept lobe hits (ObscuranceSettings::keptRaySamples, lib/kept_rays.glsl) let an added light
// follow the glossy floor's specular paths without tracing their lobe rays: the same paths, vertex
// for vertex, so the same transport bit for bit as following them by tracing again, with fewer rays.
TEST_F(Relight, AddedLightByTheKeptPathHitsEqualsTracingThePathsAgain) {
  RoomLights glossy;
  glossy.glossyFloor = true;
  scene_ = room(glossy);
  bvh_ = bvh::build(render::triangleSoup(scene_));
  std::vector<render::Transport> transports;
  std::vector<std::uint64_t> specularRays;
  for (std::uint32_t kept : {0u, 32u}) {
    render::ObscuranceSettings settings = roomSettings(7);
    settings.keptRaySamples = kept;
    render::ObscuranceRenderer r(context(), scene_, bvh_, settings);
    ASSERT_EQ(r.frame().contents().keptRaySamples, kept);
    r.render();
    const std::uint64_t before = r.stats().passes.at("specular").rays;
    r.addLight(addedLight());
    specularRays.push_back(r.stats().passes.at("specular").rays - before);
    EXPECT_EQ(r.stats().truncatedTraversals, 0u);
    transports.push_back(r.transport());
  }
  const render::Transport &traced = transports[0], &replayed = transports[1];
  ASSERT_EQ(traced.specularDirect.size(), replayed.specularDirect.size());
  const std::size_t added = traced.specularDirect.size() - 1;
  std::size_t lit = 0;
  for (std::size_t p = 0; p < traced.pixels(); ++p) {
    ASSERT_EQ(std::memcmp(&traced.specularDirect[added][p], &replayed.specularDirect[added][p], sizeof(glm::vec3)), 0)
        << "pixel " << p;
    ASSERT_EQ(std::memcmp(&traced.direct[added][p], &replayed.direct[added][p], sizeof(glm::vec3)), 0) << "pixel " << p;
    lit += traced.specularDirect[added][p].x > 0.0f ? 1 : 0;
  }
  EXPECT_GT(lit, 0u) << "the added light reaches the camera through the floor";
  // Traced again: a lobe ray and a shadow ray per vertex; replayed, the shadow rays alone.
  EXPECT_GT(specularRays[1], 0u);
  EXPECT_LT(specularRays[1], specularRays[0]);
}

// An emissive quad is a light and an object: its light is traced at every pixel, and the pixels
// its surface can change (seen, shadowing, occluding) are retraced for every light. Its triangles
// in a rebuilt tree (diffuse floor) or hung into the tree before (glossy floor, as edits do:
// bvh/insert.h).
TEST_F(Relight, AddedEmissiveQuadMatchesAFreshRenderWithIt) {
  for (bool glossyFloor : {false, true}) {
    SCOPED_TRACE(glossyFloor ? "glossy floor, the quad inserted into the tree" : "diffuse floor, the tree rebuilt");
    renderer_.reset();
    RoomLights lights;
    lights.glossyFloor = glossyFloor;
    auto& r = base(lights);
    edited_ = scene_;
    const std::size_t object = scene::insertEmissiveQuad(edited_, kPanel);
    if (glossyFloor) {
      const scene::SceneObject& quad = edited_.objects[object];
      std::vector<std::uint32_t> ids;
      bvh::TriangleSoup added;
      const bvh::TriangleSoup all = render::triangleSoup(edited_);
      for (std::uint32_t id = quad.firstTriangle; id < quad.firstTriangle + quad.triangleCount; ++id) {
        ids.push_back(id);
        added.v0.push_back(all.v0[id]);
        added.v1.push_back(all.v1[id]);
        added.v2.push_back(all.v2[id]);
      }
      editedBvh_ = bvh_;
      ASSERT_TRUE(bvh::insertTriangles(editedBvh_, ids, added));
      bvh::IncrementalRefit(editedBvh_).refit(editedBvh_, ids, added);
    } else {
      editedBvh_ = bvh::build(render::triangleSoup(edited_));
    }
    const std::uint64_t retraced = r.addEmitter(edited_, editedBvh_, {scene::objectBounds(edited_, object)});
    r.compose();
    EXPECT_EQ(r.lightIndex("panel"), 2u) << "area lights first: after the lamps, before the bulb";
    EXPECT_EQ(r.lightIndex("bulb"), 3u);
    EXPECT_GT(retraced, 0u);
    EXPECT_LT(retraced, 48u * 36u) << "only the pixels the quad's surface can change";
    EXPECT_EQ(r.stats().truncatedTraversals, 0u);
    RoomLights edited = lights;
    edited.withPanel = true;
    expectStatisticallyEqual(r.image(), edited);
    // The panel's light reaches the clean pixels too: as many pixels get some of it as in a fresh
    // render (the block means above are dominated by the panel's own noise; without the clean
    // pixels' rays this count halves).
    scene::Scene freshScene = room(edited);
    bvh::Bvh freshBvh = bvh::build(render::triangleSoup(freshScene));
    render::ObscuranceRenderer fresh(context(), freshScene, freshBvh, roomSettings(11));
    fresh.render();
    auto lit = [](const std::vector<glm::vec3>& transport) {
      return std::count_if(transport.begin(), transport.end(), [](glm::vec3 v) { return v.x + v.y + v.z > 0.0f; });
    };
    const auto litRelit = lit(r.transport().direct[2]), litFresh = lit(fresh.transport().direct[fresh.lightIndex("panel")]);
    EXPECT_GT(static_cast<double>(litRelit), 0.95 * static_cast<double>(litFresh)) << litRelit << " vs " << litFresh;
  }
}

// The relighting paper's shadow sampling: every light alone, 4 rays per hit, up to 64 in penumbrae.
TEST_F(Relight, PerLightShadowSamplingMatchesSelectionSampling) {
  for (bool glossyFloor : {false, true}) { // with a glossy floor, along specular paths too
    SCOPED_TRACE(glossyFloor ? "glossy floor" : "diffuse floor");
    RoomLights lights;
    lights.glossyFloor = glossyFloor;
    auto settings = roomSettings(7);
    settings.shadowSampling = render::ShadowSampling::PerLight;
    scene::Scene s = room(lights);
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    const auto perLight = renderObscurances(context(), s, tree, settings);
    EXPECT_EQ(perLight.stats.truncatedTraversals, 0u);
    expectStatisticallyEqual(perLight.image, lights);
  }
}

TEST_F(Relight, PerLightTransportIgnoresTheOtherLightsPowers) {
  // Two rooms that differ only in lamp B's emission: lamp A's D_s is the same bits with per-light
  // sampling, and not with selection by power (whose choice of light depends on every power).
  auto transportOfLampA = [&](render::ShadowSampling sampling, glm::vec3 lampB) {
    RoomLights lights;
    lights.lampB = lampB;
    scene::Scene s = room(lights);
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    auto settings = roomSettings(7);
    settings.shadowSampling = sampling;
    render::ObscuranceRenderer r(context(), s, tree, settings);
    r.render();
    return r.transport().direct[r.lightIndex("lampA")];
  };
  const auto same = [](const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
  };
  EXPECT_TRUE(same(transportOfLampA(render::ShadowSampling::PerLight, glm::vec3(2.0f)),
                   transportOfLampA(render::ShadowSampling::PerLight, glm::vec3(20.0f))));
  EXPECT_FALSE(same(transportOfLampA(render::ShadowSampling::Selection, glm::vec3(2.0f)),
                    transportOfLampA(render::ShadowSampling::Selection, glm::vec3(20.0f))));
}

// The same along specular paths: with per-light sampling every light follows the glossy floor's
// paths in a dispatch of its own, so lamp A's S_s is the same bits whatever lamp B emits.
TEST_F(Relight, PerLightSpecularTransportIgnoresTheOtherLightsPowers) {
  auto specularOfLampA = [&](render::ShadowSampling sampling, glm::vec3 lampB) {
    RoomLights lights;
    lights.lampB = lampB;
    lights.glossyFloor = true;
    scene::Scene s = room(lights);
    bvh::Bvh tree = bvh::build(render::triangleSoup(s));
    auto settings = roomSettings(7);
    settings.spp = 8;
    settings.shadowSampling = sampling;
    render::ObscuranceRenderer r(context(), s, tree, settings);
    r.render();
    EXPECT_TRUE(r.specular());
    EXPECT_EQ(r.stats().truncatedTraversals, 0u);
    return r.transport().specularDirect[r.lightIndex("lampA")];
  };
  const auto same = [](const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0;
  };
  const auto perLight = specularOfLampA(render::ShadowSampling::PerLight, glm::vec3(2.0f));
  double sum = 0.0;
  for (const auto& v : perLight) sum += v.x + v.y + v.z;
  EXPECT_GT(sum, 0.0) << "lamp A is seen along the floor's specular paths";
  EXPECT_TRUE(same(perLight, specularOfLampA(render::ShadowSampling::PerLight, glm::vec3(20.0f))));
  EXPECT_FALSE(same(specularOfLampA(render::ShadowSampling::Selection, glm::vec3(2.0f)),
                    specularOfLampA(render::ShadowSampling::Selection, glm::vec3(20.0f))));
}

// The fast path a light edit takes (resolved RGB9E5 transport, one light-mix pass) shows what the
// full compose + tonemap shows, to 2 display levels (a term keeps 2^-9 of its pixel's largest
// channel; sRGB at 8 bits steps by about 2^-8 near white), before and after light edits.
class LightMix : public Relight {
protected:
  void expectDisplaysAgree(render::ObscuranceRenderer& r, float exposure) {
    r.compose(exposure);
    const auto full = r.display();
    r.composeDisplay(exposure);
    const auto fast = r.display();
    ASSERT_EQ(full.size(), fast.size());
    EXPECT_LE(largestChannelDifference(full, fast), 2);
  }
};

TEST_F(LightMix, FastDisplayMatchesTheFullComposeAcrossEdits) {
  auto& r = base();
  expectDisplaysAgree(r, 0.0f);
  std::vector<glm::vec3> e = r.emissions();
  e[light("lampA")] *= glm::vec3(0.2f, 1.5f, 3.0f);
  r.setEmissions(e);
  expectDisplaysAgree(r, 1.0f);
  r.addLight(addedLight());
  expectDisplaysAgree(r, -0.5f);
  r.removeLight(light("bulb"));
  expectDisplaysAgree(r, 0.0f);
}

// lightmix.comp reads four pixels per invocation: a frame whose bands hold pixel counts that are
// not multiples of four (47 x 35 in bands of a few rows) shows every pixel the same way.
TEST_F(LightMix, OddSizedBandsShowEveryPixel) {
  scene_ = room({});
  bvh_ = bvh::build(render::triangleSoup(scene_));
  auto settings = roomSettings(7);
  settings.width = 47;
  settings.height = 35;
  settings.spp = 4;
  settings.maxBufferBytes = 47 * 6 * 32 * 4; // a few rows of 47 pixels per band
  renderer_ = std::make_unique<render::ObscuranceRenderer>(context(), scene_, bvh_, settings);
  ASSERT_GT(renderer_->layout().bandCount(), 2u);
  bool oddBand = false;
  for (std::uint32_t b = 0; b < renderer_->layout().bandCount(); ++b)
    oddBand = oddBand || renderer_->layout().bandPixels(b) % 4 != 0;
  ASSERT_TRUE(oddBand);
  renderer_->render();
  expectDisplaysAgree(*renderer_, 0.0f);
  std::vector<glm::vec3> e = renderer_->emissions();
  e[renderer_->lightIndex("lampB")] *= 3.0f;
  renderer_->setEmissions(e);
  expectDisplaysAgree(*renderer_, 0.5f);
}

TEST_F(LightMix, ALightEditResolvesNothingAgain) {
  auto& r = base();
  r.composeDisplay();
  const auto before = r.stats();
  std::vector<glm::vec3> e = r.emissions();
  e[light("lampB")] *= 0.5f;
  r.setEmissions(e);
  r.composeDisplay();
  const auto after = r.stats();
  EXPECT_EQ(after.passes.at("resolve").gpuMs, before.passes.at("resolve").gpuMs) << "no resolve after a light edit";
  EXPECT_GT(after.passes.at("lightmix").gpuMs, before.passes.at("lightmix").gpuMs);
}

} // namespace
} // namespace obscura::test
