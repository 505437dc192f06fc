// The Seen ambient model (render/scene_data/reached_surfaces.h, ambient.h): the first bounce of I_a
// fitted to the light the lamp's landing points send to the surfaces the camera sees.
//   - Its scale: in a closed room of one reflectance with a vanishing dmax (W_c = R everywhere),
//     the fit is the mean over the seen points of E_1(P) / (pi R). The test measures E_1
//     independently (cosine rays from the seen points, the lamp's direct irradiance where they
//     land, by sampling the lamp's area) and compares.
//   - What it fixes: a lamp in a closed room the camera cannot see. The reached I_a still lights
//     the camera's room with it (one constant per light for the whole scene); the seen one adds
//     nothing there.
#include <cmath>
#include <numbers>
#include <optional>
#include <random>

#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "render/scene_data/ambient.h"
#include "render/scene_data/reached_surfaces.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// A closed cube [c, c + 2]^3 with every face facing inward.
void closedRoom(SceneBuilder& b, glm::vec3 c, std::uint32_t material) {
  b.quad(c, {0, 0, 2}, {2, 0, 0}, material);
  b.quad(c + glm::vec3(0, 2, 0), {2, 0, 0}, {0, 0, 2}, material);
  b.quad(c, {0, 2, 0}, {0, 0, 2}, material);
  b.quad(c + glm::vec3(2, 0, 0), {0, 0, 2}, {0, 2, 0}, material);
  b.quad(c, {2, 0, 0}, {0, 2, 0}, material);
  b.quad(c + glm::vec3(0, 0, 2), {0, 2, 0}, {2, 0, 0}, material);
}

// The lamp's quad under the lit room's ceiling, facing -y.
const glm::vec3 kLampCorner{0.8f, 1.99f, 0.8f}, kLampU{0.4f, 0, 0}, kLampV{0, 0, 0.4f};

// A lit room at the origin (reflectance 0.5) with the lamp, and a closed dark room beside it.
scene::Scene litAndDarkRooms() {
  SceneBuilder b;
  closedRoom(b, {0, 0, 0}, b.lambertian(glm::vec3(0.5f)));
  closedRoom(b, {5, 0, 0}, b.lambertian(glm::vec3(0.5f)));
  b.quad(kLampCorner, kLampU, kLampV, b.lambertian(glm::vec3(0.0f), glm::vec3(4.0f)), "lamp");
  return b.build();
}

struct Fixture {
  scene::Scene scene = litAndDarkRooms();
  bvh::Bvh tree = bvh::build(render::triangleSoup(scene));
  render::LightSet lights = render::buildLightSet(scene);
  std::vector<glm::vec3> albedo = [this] {
    std::vector<glm::vec3> out;
    for (const auto& m : scene.materials) out.push_back(render::materialMeanAlbedo(m));
    return out;
  }();
  render::ReachedSurfaces reached{scene, tree, render::triangleReflectances(scene, albedo)};
};

render::SeenView viewFrom(glm::vec3 position, float dMax) {
  return {.position = position, .forward = {0, 0, 1}, .up = {0, 1, 0}, .yfov = 1.2f, .aspect = 1.0f, .dMax = dMax,
          .rho = gpu::kRhoSqrt, .tau = 3.0f, .colourBleeding = true, .averageReflectance = glm::vec3(0.5f)};
}

// Direct irradiance at q (normal n) from the lamp at unit emission scale: radiance L over the
// quad, sampled uniformly, with shadow rays.
double lampIrradiance(const Fixture& f, glm::vec3 q, glm::vec3 n, std::mt19937& rng) {
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const float area = glm::length(glm::cross(kLampU, kLampV));
  const double radiance = f.lights.unitFlux[0].x / (kPi * area); // one-sided Lambertian emitter
  const glm::vec3 lampNormal(0, -1, 0);
  constexpr int kSamples = 16;
  double sum = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    glm::vec3 p = kLampCorner + uni(rng) * kLampU + uni(rng) * kLampV;
    glm::vec3 d = p - q;
    float r2 = glm::dot(d, d);
    glm::vec3 w = d / std::sqrt(r2);
    float cosQ = glm::dot(n, w), cosL = -glm::dot(lampNormal, w);
    if (cosQ <= 0.0f || cosL <= 0.0f) continue;
    bvh::Ray ray{.origin = q + 1e-4f * n, .direction = (p + 1e-4f * lampNormal) - (q + 1e-4f * n), .tmin = 0.0f, .tmax = 1.0f};
    if (bvh::anyHit(f.tree, ray)) continue;
    sum += cosQ * cosL / r2;
  }
  return radiance * area * sum / kSamples;
}

// The fit's target by another estimator, for a scene of one reflectance R and a vanishing dmax
// (W_c = R everywhere): F = mean_P E_1(P) / (pi R) with E_1(P) = R mean_Q E_dir(Q) over cosine rays
// from the camera's points (a jittered grid as setSeenView's); `direct(q, n)` is E_dir at unit
// emission, `emitter` a material that reflects nothing (skipped), -1 if none.
template <class Direct>
double oneBounceFit(const scene::Scene& scene, const bvh::Bvh& tree, glm::vec3 eye, float reflectance, int emitter,
                    Direct direct, std::uint32_t seed = 12345) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  constexpr int kGrid = 24, kRays = 24;
  const float tanHalf = std::tan(0.6f);
  auto facing = [&](std::uint32_t primitive, glm::vec3 d) {
    const glm::uvec3 t = scene.triangles[primitive];
    glm::vec3 n = glm::normalize(glm::cross(scene.positions[t.y] - scene.positions[t.x], scene.positions[t.z] - scene.positions[t.x]));
    return glm::dot(n, d) > 0.0f ? -n : n;
  };
  double sum = 0.0;
  int points = 0;
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      glm::vec3 d = glm::normalize(glm::vec3((2.0f * (x + uni(rng)) / kGrid - 1.0f) * tanHalf,
                                             (1.0f - 2.0f * (y + uni(rng)) / kGrid) * tanHalf, 1.0f));
      bvh::Hit h = bvh::closestHit(tree, {.origin = eye, .direction = d});
      if (!h.hit() || int(scene.triangleMaterial[h.primitive]) == emitter) continue; // R = 0 weighs nothing
      const glm::vec3 n = facing(h.primitive, d), p = eye + h.t * d;
      glm::vec3 a = std::abs(n.x) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
      glm::vec3 tx = glm::normalize(glm::cross(a, n)), ty = glm::cross(n, tx);
      double e1 = 0.0;
      for (int k = 0; k < kRays; ++k) {
        float u1 = uni(rng), phi = 2.0f * kPi * uni(rng), rr = std::sqrt(u1);
        glm::vec3 w = rr * std::cos(phi) * tx + rr * std::sin(phi) * ty + std::sqrt(1.0f - u1) * n;
        bvh::Hit q = bvh::closestHit(tree, {.origin = p + 1e-4f * n, .direction = w});
        if (!q.hit() || int(scene.triangleMaterial[q.primitive]) == emitter) continue;
        const glm::vec3 nq = facing(q.primitive, w);
        e1 += reflectance * direct(p + 1e-4f * n + q.t * w + 1e-4f * nq, nq, rng);
      }
      sum += e1 / kRays / (kPi * reflectance);
      ++points;
    }
  return sum / points;
}

TEST(SeenAmbient, FirstBounceFitEqualsTheOneBounceIrradianceTheCameraSees) {
  Fixture f;
  const glm::vec3 eye(1.0f, 1.0f, 0.1f);
  const float dMax = 1e-4f; // every obscurance ray leaves dmax: W_c = R_ave = R at every seen point
  f.reached.setSeenView(viewFrom(eye, dMax));
  ASSERT_GT(f.reached.seenPoints(), 500u);
  const render::LightReach r = f.reached.measure(f.lights, 0);
  ASSERT_TRUE(r.seenFitted);
  const double expected = oneBounceFit(f.scene, f.tree, eye, 0.5f, 2, [&](glm::vec3 q, glm::vec3 n, std::mt19937& rng) {
    return lampIrradiance(f, q, n, rng);
  });
  // Both are means over ~550 seen points by different estimators (measured 1.2 % apart; the
  // virtual point lights' clamp r_c, 0.09 m here, lowers the fit a little). A lost or doubled
  // factor (pi, R, the flux per landing) is 2-3x off.
  EXPECT_NEAR(r.seenFirstBounce.x, expected, 0.08 * expected);
  EXPECT_NEAR(r.seenFirstBounce.y, r.seenFirstBounce.x, 1e-6 * r.seenFirstBounce.x) << "a grey room";

  // The reached model's first bounce, flux / (pi A_s), for scale: the lit room's mean irradiance.
  const double reachedFirst = f.lights.unitFlux[0].x / (kPi * r.area);
  EXPECT_GT(r.seenFirstBounce.x, 0.3 * reachedFirst);
  EXPECT_LT(r.seenFirstBounce.x, 3.0 * reachedFirst);
}

// A roofless 4 x 3 x 4 m room on a 200 m ground, the camera inside, lit from outside the scene:
// of the sun's or the sky's rays, spread over the 200 m world, almost none land in the room
// (classroom's sun through its windows is the real case). Their first bounce is gathered from
// where the seen points' rays land (gatheredFirstBounce).
struct RooflessRoom {
  scene::Scene scene;
  bvh::Bvh tree;
  render::LightSet lights;
  std::vector<glm::vec3> albedo;
  static constexpr glm::vec3 kEye{2.0f, 1.5f, 0.2f};

  // Lit by the sun travelling along `sunTravels`, or by a constant sky of radiance `sky`.
  RooflessRoom(std::optional<glm::vec3> sunTravels, glm::vec3 sky) {
    SceneBuilder b;
    const auto grey = b.lambertian(glm::vec3(0.5f), glm::vec3(0.0f), true);
    b.quad({-100, 0, -100}, {0, 0, 200}, {200, 0, 0}, grey); // the ground, facing +y
    b.quad({0, 0, 0}, {0, 3, 0}, {0, 0, 4}, grey);            // the walls (two-sided)
    b.quad({4, 0, 0}, {0, 0, 4}, {0, 3, 0}, grey);
    b.quad({0, 0, 0}, {4, 0, 0}, {0, 3, 0}, grey);
    b.quad({0, 0, 4}, {0, 3, 0}, {4, 0, 0}, grey);
    if (sunTravels) b.directionalLight(*sunTravels, glm::vec3(1.0f), 1.0f);
    scene = b.build();
    scene.background = sky;
    tree = bvh::build(render::triangleSoup(scene));
    lights = render::buildLightSet(scene);
    for (const auto& m : scene.materials) albedo.push_back(render::materialMeanAlbedo(m));
  }
  render::LightReach measured() const {
    render::ReachedSurfaces reached(scene, tree, render::triangleReflectances(scene, albedo));
    reached.setSeenView(viewFrom(kEye, 1e-4f));
    return reached.measure(lights, 0);
  }
};

// Both sides are means over ~570 seen points, by independent estimators. Over 8 seeds of the seen
// grid the fit is 0.99 of the reference on average (sun and sky alike), with a spread of 2.7 %;
// the reference's own spread over 8 of its seeds is 1.2 %; together 3 %: asserted within 10 %.
// The beams across the seen box that the sun and the sky used before gave 0.64-0.97 of it over 12
// seeds, 0.75 on average (the virtual point lights' clamp r_c next to the seen points); without
// any, the fit is 0.
TEST(SeenAmbient, SunOnASmallRoomInALargeWorldIsGatheredWhereTheSeenPointsLook) {
  const glm::vec3 sunTravels = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  const RooflessRoom room(sunTravels, glm::vec3(0.0f));
  const render::LightReach r = room.measured();
  ASSERT_TRUE(r.seenFitted);
  const double expected = oneBounceFit(room.scene, room.tree, RooflessRoom::kEye, 0.5f, -1, [&](glm::vec3 q, glm::vec3 n, std::mt19937&) {
    const float cosine = -glm::dot(n, sunTravels);
    if (cosine <= 0.0f) return 0.0;
    return bvh::anyHit(room.tree, {.origin = q, .direction = -sunTravels}) ? 0.0 : static_cast<double>(cosine);
  });
  ASSERT_GT(expected, 0.0);
  EXPECT_NEAR(r.seenFirstBounce.x, expected, 0.10 * expected);
}

// The same room under a constant sky (radiance 1): E_dir(Q) = pi x the share of Q's cosine
// directions that leave the scene. The reference samples 16 of them per landing, the fit one.
TEST(SeenAmbient, SkyOnASmallRoomInALargeWorldIsGatheredWhereTheSeenPointsLook) {
  const RooflessRoom room(std::nullopt, glm::vec3(1.0f));
  ASSERT_EQ(room.lights.lights[0].info.x, gpu::kLightBackground);
  const render::LightReach r = room.measured();
  ASSERT_TRUE(r.seenFitted);
  const double expected = oneBounceFit(room.scene, room.tree, RooflessRoom::kEye, 0.5f, -1, [&](glm::vec3 q, glm::vec3 n, std::mt19937& rng) {
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    glm::vec3 a = std::abs(n.x) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    glm::vec3 tx = glm::normalize(glm::cross(a, n)), ty = glm::cross(n, tx);
    constexpr int kRays = 16;
    int open = 0;
    for (int k = 0; k < kRays; ++k) {
      float u1 = uni(rng), phi = 2.0f * kPi * uni(rng), rr = std::sqrt(u1);
      glm::vec3 w = rr * std::cos(phi) * tx + rr * std::sin(phi) * ty + std::sqrt(1.0f - u1) * n;
      open += bvh::anyHit(room.tree, {.origin = q, .direction = w}) ? 0 : 1;
    }
    return static_cast<double>(kPi) * open / kRays;
  });
  ASSERT_GT(expected, 0.0);
  EXPECT_NEAR(r.seenFirstBounce.x, expected, 0.10 * expected);
}

TEST(SeenAmbient, ALampTheCamerasRoomCannotSeeAddsNoAmbientLightThere) {
  Fixture f;
  f.reached.setSeenView(viewFrom({6.0f, 1.0f, 0.1f}, 0.5f)); // inside the dark room
  render::AmbientTerm term = render::computeAmbient(f.scene, f.lights, f.albedo, true);
  term.reach = {f.reached.measure(f.lights, 0)};
  ASSERT_TRUE(term.reach[0].seenFitted);
  EXPECT_EQ(term.reach[0].seenFirstBounce, glm::vec3(0.0f));
  term.model = render::AmbientModel::Reached;
  render::updateAmbientWeights(term, f.lights, true);
  EXPECT_GT(term.weight[0].x, 0.0f) << "the reached I_a is one constant for the whole scene";
  term.model = render::AmbientModel::Seen;
  render::updateAmbientWeights(term, f.lights, true);
  EXPECT_EQ(term.weight[0], glm::vec3(0.0f)) << "the camera's room gets none of the lamp's ambient light";
}

} // namespace
} // namespace obscura::test
