// What a light reaches (render/scene_data/reached_surfaces.h) measured with its rays traced on the
// device (GpuRayBatch: trace.comp through the scene's buffers, as a renderer does) against the
// same measurement on the CPU's BVH (CpuRayBatch, the twin). The two traversals agree on a ray's
// hit up to rounding, so a ray that grazes an edge may land on the neighbouring triangle: the
// tolerances allow a few such rays in a thousand and nothing more.
#include <bit>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "gpu_test.h"
#include "render/gpu_ray_batch.h"
#include "render/scene_data/ambient.h"
#include "render/scene_data/bvh_layout.h"
#include "render/scene_data/ray_rounds.h"
#include "render/scene_data/reached_surfaces.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {

std::vector<glm::vec3> reflectances(const scene::Scene& s) {
  std::vector<glm::vec3> albedo;
  for (const auto& m : s.materials) albedo.push_back(render::materialMeanAlbedo(m));
  return render::triangleReflectances(s, albedo);
}

// The Cornell box's own lamp, a point light, a spot and the sun (through the open front): every
// way a light's points and directions are drawn.
render::LightSet everyKindOfLight(const scene::Scene& s) {
  render::LightSet lights = render::buildLightSet(s);
  scene::PunctualLight point{.name = "bulb", .type = scene::PunctualType::Point, .intensity = 3.0f,
                             .position = {0.3f, 1.2f, 0.2f}};
  scene::PunctualLight spot{.name = "spot", .type = scene::PunctualType::Spot, .intensity = 5.0f,
                            .position = {-0.4f, 1.6f, 0.3f}, .direction = glm::normalize(glm::vec3(0.3f, -1.0f, -0.2f)),
                            .outerConeAngle = 0.5f};
  scene::PunctualLight sun{.name = "sun", .type = scene::PunctualType::Directional, .intensity = 2.0f,
                           .direction = glm::normalize(glm::vec3(-0.2f, -0.3f, -1.0f))};
  for (const auto& l : {point, spot, sun}) render::appendPunctual(lights, l, s.bounds);
  return lights;
}

render::SeenView cornellView(const scene::Scene& s) {
  const scene::Camera& c = s.cameras.front();
  return {.position = c.position, .forward = c.forward, .up = c.up, .yfov = c.yfov, .aspect = 1.0f, .dMax = 0.5f};
}

// The Cornell box with every kind of light, its tree as the device's traversal wants it, and its
// buffers on the device with a GpuRayBatch over them.
class ReachOnDevice : public GpuTest {
protected:
  ReachOnDevice()
      : scene_(scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"))),
        tree_(bvh::build(render::triangleSoup(scene_), render::treeOptionsFor(render::traversalFor(context())))),
        lights_(everyKindOfLight(scene_)), buffers_(context(), scene_, tree_), device_(context(), buffers_) {}
  const scene::Scene scene_;
  const bvh::Bvh tree_;
  const render::LightSet lights_;
  const render::SceneBuffers buffers_;
  render::GpuRayBatch device_;
};

TEST_F(ReachOnDevice, MatchesTheCpuTwinForEveryKindOfLight) {
  const scene::Scene& s = scene_;
  const bvh::Bvh& tree = tree_;
  const render::LightSet& lights = lights_;
  render::GpuRayBatch& device = device_;
  render::ReachedSurfaces onDevice(s, tree, reflectances(s), /*copyBvh=*/false);
  render::ReachedSurfaces onCpu(s, tree, reflectances(s));
  onDevice.setSeenView(device, cornellView(s));
  onCpu.setSeenView(cornellView(s));
  ASSERT_EQ(onDevice.seenPoints(), onCpu.seenPoints()) << "the camera's grid points hit the same surfaces";
  ASSERT_GT(onCpu.seenPoints(), 0u);

  for (std::size_t light = 0; light < lights.size(); ++light) {
    SCOPED_TRACE(lights.names[light]);
    const render::LightReach gpu = onDevice.measure(device, lights, light);
    const render::LightReach cpu = onCpu.measure(lights, light);
    ASSERT_EQ(gpu.rays.landingPrimitive.size(), cpu.rays.landingPrimitive.size());
    std::size_t sameLanding = 0, sameSeenTry = 0;
    for (std::size_t i = 0; i < cpu.rays.landingPrimitive.size(); ++i)
      sameLanding += gpu.rays.landingPrimitive[i] == cpu.rays.landingPrimitive[i] ? 1 : 0;
    for (std::size_t j = 0; j < cpu.rays.firstSeenTry.size(); ++j)
      sameSeenTry += gpu.rays.firstSeenTry[j] == cpu.rays.firstSeenTry[j] ? 1 : 0;
    EXPECT_GE(sameLanding, cpu.rays.landingPrimitive.size() * 995 / 1000) << "light rays landing elsewhere";
    EXPECT_GE(sameSeenTry, cpu.rays.firstSeenTry.size() * 995 / 1000) << "surface samples seeing otherwise";
    EXPECT_GT(cpu.fraction, 0.0);
    EXPECT_NEAR(gpu.fraction, cpu.fraction, 0.005);
    EXPECT_NEAR(gpu.escapeDirect, cpu.escapeDirect, 0.005);
    EXPECT_NEAR(gpu.escapeBounce, cpu.escapeBounce, 0.01);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(gpu.reflectance[c], cpu.reflectance[c], 0.01f);
    ASSERT_TRUE(gpu.seenFitted && cpu.seenFitted);
    for (int c = 0; c < 3; ++c) {
      EXPECT_GT(cpu.seenFirstBounce[c], 0.0f);
      EXPECT_NEAR(gpu.seenFirstBounce[c], cpu.seenFirstBounce[c], 0.03f * cpu.seenFirstBounce[c]);
    }
  }
}

// Every light on a thread of its own with their stages traced together in one submission per
// round (RayRounds, as LightReachModel measures them on the device) finds what each light measured
// alone finds, ray for ray: merging the rays changes no ray's hit.
TEST_F(ReachOnDevice, LightsMeasuredTogetherEqualEachMeasuredAlone) {
  const scene::Scene& s = scene_;
  const render::LightSet& lights = lights_;
  render::GpuRayBatch& device = device_;
  render::ReachedSurfaces reached(s, tree_, reflectances(s), false);
  reached.setSeenView(device, cornellView(s));
  std::vector<render::LightReach> alone;
  for (std::size_t light = 0; light < lights.size(); ++light) alone.push_back(reached.measure(device, lights, light));

  const std::uint64_t raysBefore = device.rays();
  std::vector<render::LightReach> together(lights.size());
  {
    render::RayRounds rounds(device, lights.size());
    std::vector<std::thread> threads;
    for (std::size_t light = 0; light < lights.size(); ++light)
      threads.emplace_back([&, light] {
        render::RayRounds::Member member(rounds);
        together[light] = reached.measure(member, lights, light);
      });
    for (auto& t : threads) t.join();
  }
  std::uint64_t traced = 0;
  for (std::size_t light = 0; light < lights.size(); ++light) {
    SCOPED_TRACE(lights.names[light]);
    EXPECT_EQ(together[light].rays.landingPrimitive, alone[light].rays.landingPrimitive);
    EXPECT_EQ(together[light].rays.firstSeenTry, alone[light].rays.firstSeenTry);
    EXPECT_EQ(together[light].rays.tryBlockedAt.size(), alone[light].rays.tryBlockedAt.size());
    EXPECT_EQ(together[light].area, alone[light].area);
    EXPECT_EQ(together[light].escapeBounce, alone[light].escapeBounce);
    EXPECT_EQ(together[light].seenFirstBounce, alone[light].seenFirstBounce);
    traced += together[light].rays.traced;
  }
  EXPECT_EQ(device.rays() - raysBefore, traced) << "every ray traced once, through the device";
}

// An edit's re-measurement on the device, re-tracing only the rays the move can change, gives
// exactly what measuring the moved scene on the device from scratch gives: the device's traversal
// finds the same hit for a ray whatever else moved.
TEST_F(ReachOnDevice, RemeasureAfterAMoveEqualsMeasuringTheMovedScene) {
  const render::LightSet& lights = lights_;
  render::ReachedSurfaces reached(scene_, tree_, reflectances(scene_), false);
  std::vector<render::LightReach> before;
  for (std::size_t light = 0; light < lights.size(); ++light) before.push_back(reached.measure(device_, lights, light));

  const MovedObject m = moveAndRefit(scene_, tree_, "cube_2", {0.3f, 0.0f, 0.0f}, 1e-3f);
  const std::vector<scene::Bounds>& changed = m.changed;
  const render::SceneBuffers movedBuffers(context(), m.scene, m.tree);
  render::GpuRayBatch movedDevice(context(), movedBuffers);
  render::ReachedSurfaces movedReach(m.scene, m.tree, reflectances(m.scene), false);

  for (std::size_t light = 0; light < lights.size(); ++light) {
    SCOPED_TRACE(lights.names[light]);
    const render::LightReach fresh = movedReach.measure(movedDevice, lights, light);
    const render::LightReach replayed = movedReach.remeasure(movedDevice, reached, before[light], lights, light, changed);
    expectReplayEqualsFresh(replayed, fresh);
    EXPECT_LT(replayed.rays.traced, fresh.rays.traced) << "the replay traced every ray again";
  }
}

} // namespace
} // namespace obscura::test
