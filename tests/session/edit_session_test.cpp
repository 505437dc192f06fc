// The edit session (session/edit_session.h) in-process: lights addressed by name while the
// renderer's light order shifts under them, the report of each edit, refused edits that leave the
// session as it was, and an edited frame against a fresh render of the scene the session holds.
#include <algorithm>

#include <gtest/gtest.h>

#include "core/error.h"
#include "gpu_test.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/gltf_loader.h"
#include "session/edit_session.h"

namespace obscura::test {
namespace {

using session::Edit;
constexpr std::uint32_t kSize = 48;

render::ObscuranceSettings cornellSettings(const scene::Scene& scene) {
  render::ObscuranceSettings s;
  s.width = s.height = kSize;
  s.spp = 2;
  s.camera = scene.cameras.at(0);
  return s;
}

class EditSessionTest : public GpuTest {
protected:
  session::EditSession& open() {
    scene::Scene scene = scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"));
    bvh::Bvh tree = bvh::build(render::triangleSoup(scene));
    settings_ = session::editSettings(cornellSettings(scene), 4);
    session_ = std::make_unique<session::EditSession>(context(), std::move(scene), std::move(tree), settings_);
    session_->renderer().render();
    return *session_;
  }
  static Edit addBulb(const std::string& name, glm::vec3 position) {
    Edit e{.kind = Edit::Kind::AddLight, .name = name};
    e.light = {.name = name, .type = scene::PunctualType::Point, .intensity = 1.0f, .position = position};
    return e;
  }
  static Edit addPanel() {
    Edit e{.kind = Edit::Kind::AddQuad, .name = "panel"};
    e.quad = {.name = "panel", .corner = {-0.2f, 1.2f, -0.2f}, .edge1 = {0.4f, 0, 0}, .edge2 = {0, 0, 0.4f},
              .emission = glm::vec3(3.0f)};
    return e;
  }
  // The session's lights are the renderer's, in its order, each with its edited emission.
  void expectLightsInStep() {
    const auto& r = session_->renderer();
    ASSERT_EQ(session_->lights().names(), r.lights().names);
    for (std::size_t i = 0; i < session_->lights().size(); ++i)
      EXPECT_EQ(r.emissions()[i], session_->lights()[i].emission()) << session_->lights()[i].name;
  }

  render::ObscuranceSettings settings_;
  std::unique_ptr<session::EditSession> session_;
};

TEST_F(EditSessionTest, LightsKeepTheirNamesWhileTheRenderersOrderShifts) {
  auto& s = open();
  const std::string lamp = s.lights()[0].name;
  s.apply(addBulb("bulb", {0.3f, 1.5f, 0.2f}));
  const glm::vec3 bulbBase = s.lights().at("bulb").base;
  s.apply(addPanel()); // an area light: it goes before the bulb in the renderer's order
  EXPECT_LT(s.renderer().lightIndex("panel"), s.renderer().lightIndex("bulb"));
  s.apply({.kind = Edit::Kind::Scale, .name = "bulb", .scale = 0.5f});
  s.apply({.kind = Edit::Kind::Color, .name = "panel", .color = {0.5f, 0.7f, 1.0f}});
  expectLightsInStep();
  EXPECT_EQ(s.renderer().emissions()[s.renderer().lightIndex("bulb")], bulbBase * 0.5f);

  s.apply({.kind = Edit::Kind::MoveLight, .name = "bulb", .position = {-0.3f, 1.5f, 0.2f}});
  EXPECT_EQ(s.lights().at("bulb").scale, 0.5f) << "a moved light keeps its edits";
  EXPECT_EQ(s.lights().at("bulb").light.position, glm::vec3(-0.3f, 1.5f, 0.2f));
  expectLightsInStep();

  // An area light is switched off and keeps its slot; a punctual light goes.
  s.apply({.kind = Edit::Kind::RemoveLight, .name = lamp});
  s.apply({.kind = Edit::Kind::RemoveLight, .name = "bulb"});
  EXPECT_TRUE(s.lights().contains(lamp));
  EXPECT_EQ(s.lights().at(lamp).emission(), glm::vec3(0.0f));
  EXPECT_FALSE(s.lights().contains("bulb"));
  expectLightsInStep();
}

TEST_F(EditSessionTest, ReportsSayWhatEachEditTracedAndHowTheBvhFollowed) {
  auto& s = open();
  const std::uint64_t pixels = std::uint64_t(kSize) * kSize;
  auto rays = [](const session::EditReport& r) {
    std::uint64_t n = 0;
    for (const auto& [pass, count] : r.rays) n += count;
    return n;
  };

  const auto scale = s.apply({.kind = Edit::Kind::Scale, .name = s.lights()[0].name, .scale = 2.0f});
  EXPECT_EQ(scale.kind, "scale");
  EXPECT_EQ(rays(scale), 0u) << "a light's scale is a compose, no ray";
  EXPECT_EQ(scale.pixelsRetraced, 0u);
  EXPECT_FALSE(scale.bvh);

  const auto add = s.apply(addBulb("bulb", {0.3f, 1.5f, 0.2f}));
  EXPECT_EQ(add.pixelsRetraced, pixels);
  EXPECT_GT(rays(add), 0u);
  EXPECT_TRUE(add.reach) << "what the new light reaches is measured for I_a";

  const auto move = s.apply({.kind = Edit::Kind::Move, .name = "cube_2", .translate = {0.1f, 0.0f, 0.05f}});
  ASSERT_TRUE(move.bvh);
  EXPECT_EQ(move.bvh->kind, session::BvhUpdate::Kind::Refit) << "a move keeps every triangle: the BVH is refitted";
  EXPECT_GT(move.pixelsRetraced, 0u);
  EXPECT_LT(move.pixelsRetraced, pixels) << "only the pixels the box can change";

  const auto quad = s.apply(addPanel());
  ASSERT_TRUE(quad.bvh);
  EXPECT_NE(quad.bvh->kind, session::BvhUpdate::Kind::Refit) << "a quad adds triangles: the BVH is not refitted";
  EXPECT_GT(quad.pixelsRetraced, 0u);

  session::EditReport shown = s.apply({.kind = Edit::Kind::Color, .name = "panel", .color = {1.0f, 0.5f, 0.5f}});
  const double editMs = shown.totalMs;
  s.composeDisplay(shown, 0.0f);
  EXPECT_GT(shown.totalMs, editMs) << "the compose's time is added";
  EXPECT_FALSE(shown.gpuMs.empty()) << "the compose pass's GPU time";

  const auto line = move.json();
  for (const char* key : {"kind", "name", "pixels_retraced", "rays", "gpu_ms", "bvh", "reach", "host_ms", "cpu_ms", "total_ms"})
    EXPECT_TRUE(line.contains(key)) << key;
  EXPECT_GE(line["host_ms"].get<double>(), 0.0);
  EXPECT_EQ(line["cpu_ms"].get<double>(), move.cpuMs);
  // The host's CPU time, on every thread: a quad's rebuild and every light's reach are far more
  // of it than a scale's bookkeeping.
  EXPECT_GT(scale.cpuMs, 0.0);
  EXPECT_GT(quad.cpuMs, 2.0 * scale.cpuMs);
}

TEST_F(EditSessionTest, ARefusedEditLeavesTheSessionAsItWas) {
  auto& s = open();
  s.apply(addBulb("bulb", {0.3f, 1.5f, 0.2f}));
  const auto names = s.lights().names();
  const auto objects = s.scene().objects.size();
  const std::string lamp = s.lights()[0].name;
  EXPECT_THROW(s.apply({.kind = Edit::Kind::Scale, .name = "nope", .scale = 2.0f}), InputError);
  EXPECT_THROW(s.apply(addBulb("bulb", {0.0f, 1.0f, 0.0f})), InputError) << "a name taken";
  EXPECT_THROW(s.apply({.kind = Edit::Kind::MoveLight, .name = lamp}), InputError) << "only added lights move";
  EXPECT_THROW(s.apply({.kind = Edit::Kind::Move, .name = "nope"}), InputError);
  EXPECT_EQ(s.lights().names(), names);
  EXPECT_EQ(s.scene().objects.size(), objects);
  expectLightsInStep();
  const auto ok = s.apply({.kind = Edit::Kind::Scale, .name = "bulb", .scale = 3.0f});
  EXPECT_EQ(ok.name, "bulb");
}

TEST_F(EditSessionTest, EditedFrameEqualsAFreshRenderOfTheSessionsScene) {
  auto& s = open();
  s.apply({.kind = Edit::Kind::Move, .name = "cube_2", .translate = {0.15f, 0.0f, 0.1f}});
  s.apply({.kind = Edit::Kind::Scale, .name = s.lights()[0].name, .scale = 0.7f});
  s.apply({.kind = Edit::Kind::Remove, .name = "cube_1"});
  s.renderer().compose();

  render::ObscuranceSettings settings = settings_;
  settings.keptRaySamples = 0;
  settings.spareLightSlots = 0;
  settings.dMax = s.renderer().dMax(); // by default from the free paths of the scene it was made with
  render::ObscuranceRenderer fresh(context(), s.scene(), s.bvh(), settings);
  fresh.reset();
  fresh.iterate(settings.spp);
  fresh.setEmissions(s.lights().emissions());
  fresh.compose();
  EXPECT_LE(largestChannelDifference(s.renderer().display(), fresh.display()), 1)
      << "the retraced pixels end as a full render of the edited scene makes them";
}

} // namespace
} // namespace obscura::test
