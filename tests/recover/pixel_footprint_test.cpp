// The surfaces a pixel's footprint covers (recover/pixel_footprint.h): traced against a known
// edge, and a pixel that covers two surfaces, or a surface and nothing, recovered as the mix of
// their reflectances whatever its own estimate was.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "recover/pixel_footprint.h"
#include "render/scene_data/ray_batch.h"
#include "render/scene_data/scene_buffers.h"
#include "render/test_scenes.h"

namespace obscura::test {
namespace {

constexpr int kSize = 8;

// Two quads in the plane z = 0 facing a camera 1 above it with a 90 degree field of view, so the
// 8 x 8 image spans x, y in [-1, 1] and a pixel is 0.25 across: object "left" on x < edge,
// "right" on x > edge, both up to y = top (above it nothing).
scene::Scene twoWalls(float edge, float top) {
  SceneBuilder b;
  const std::uint32_t m = b.lambertian(glm::vec3(0.5f));
  b.quad({-1.0f, -1.0f, 0.0f}, {edge + 1.0f, 0.0f, 0.0f}, {0.0f, top + 1.0f, 0.0f}, m);
  b.quad({edge, -1.0f, 0.0f}, {1.0f - edge, 0.0f, 0.0f}, {0.0f, top + 1.0f, 0.0f}, m);
  scene::Scene s = b.build();
  s.objects = {{.name = "left", .firstTriangle = 0, .triangleCount = 2},
               {.name = "right", .firstTriangle = 2, .triangleCount = 2}};
  return s;
}

scene::Camera overTheWalls() {
  return lookCamera({0.0f, 0.0f, 1.0f}, {0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, 0.0f}, 0.5f * std::numbers::pi_v<float>);
}

recover::PixelFootprints footprintsOf(const scene::Scene& walls) {
  const bvh::Bvh tree = bvh::build(render::triangleSoup(walls));
  render::CpuRayBatch rays(tree);
  return recover::traceFootprints(walls, rays, overTheWalls(), kSize, kSize);
}

std::size_t at(int x, int y) { return std::size_t(y) * kSize + std::size_t(x); }

int pointsOn(const recover::PixelFootprints& f, std::size_t p, std::int32_t object) {
  int n = 0;
  for (int k = 0; k < recover::PixelFootprints::kPoints; ++k) n += f.object[p * recover::PixelFootprints::kPoints + k] == object;
  return n;
}

TEST(PixelFootprint, APixelAnEdgeCrossesIsSharedByItsTwoSurfacesInProportion) {
  // Column 4 spans x in [0, 0.25]; an edge at x = 0.125 leaves half of its point columns on each
  // side, one at x = 0.19 three quarters on the left. Rows above y = 0.5 (row 1 spans [0.5, 0.75])
  // see nothing; the edge at y = 0.5625 leaves a quarter of row 1's point rows on the walls.
  constexpr int all = recover::PixelFootprints::kPoints;
  const recover::PixelFootprints half = footprintsOf(twoWalls(0.125f, 0.5625f));
  for (int y = 2; y < kSize; ++y) {
    EXPECT_EQ(pointsOn(half, at(4, y), 0), all / 2) << "row " << y;
    EXPECT_EQ(pointsOn(half, at(4, y), 1), all / 2) << "row " << y;
    EXPECT_FALSE(half.whole(at(4, y)));
    EXPECT_TRUE(half.whole(at(3, y)));
    EXPECT_TRUE(half.whole(at(5, y)));
    EXPECT_EQ(pointsOn(half, at(3, y), 0), all);
    EXPECT_EQ(pointsOn(half, at(5, y), 1), all);
  }
  EXPECT_EQ(pointsOn(half, at(0, 1), 0), all / 4);
  EXPECT_EQ(pointsOn(half, at(0, 1), -1), all * 3 / 4);
  EXPECT_EQ(pointsOn(half, at(0, 0), -1), all);
  EXPECT_TRUE(half.whole(at(0, 0))); // on nothing, wholly
  const recover::PixelFootprints threeQuarters = footprintsOf(twoWalls(0.19f, 1.0f));
  EXPECT_EQ(pointsOn(threeQuarters, at(4, 5), 0), all * 3 / 4);
  EXPECT_EQ(pointsOn(threeQuarters, at(4, 5), 1), all / 4);
}

TEST(PixelFootprint, AnEdgeTheCoarseGridMissesIsFoundFromTheNeighbourAcrossIt) {
  // An edge at x = 0.03 in column 4 ([0, 0.25]) passes left of all its coarse points (the first at
  // 0.25 / 8 = 0.031), so on the coarse grid column 4 is wholly "right" and column 3 wholly
  // "left": two whole pixels of different objects, one of which holds the edge. Both take the
  // fine grid, whose first point column (at 0.0156) is on the left: an eighth of the footprint.
  static_assert(recover::PixelFootprints::kCoarseGrid == 4 && recover::PixelFootprints::kGrid == 8);
  constexpr int all = recover::PixelFootprints::kPoints;
  const bvh::Bvh tree = bvh::build(render::triangleSoup(twoWalls(0.03f, 1.0f)));
  render::CpuRayBatch rays(tree);
  std::size_t refined = 0;
  const recover::PixelFootprints f =
      recover::traceFootprints(twoWalls(0.03f, 1.0f), rays, overTheWalls(), kSize, kSize, &refined);
  EXPECT_EQ(refined, std::size_t(2 * kSize)); // columns 3 and 4; each other one sees what its neighbours see
  for (int y = 0; y < kSize; ++y) {
    EXPECT_EQ(pointsOn(f, at(4, y), 0), all / 8) << "row " << y;
    EXPECT_EQ(pointsOn(f, at(4, y), 1), all * 7 / 8) << "row " << y;
    EXPECT_FALSE(f.whole(at(4, y)));
    EXPECT_EQ(pointsOn(f, at(3, y), 0), all);
    EXPECT_EQ(pointsOn(f, at(0, y), 0), all); // away from the edge: filled from the coarse grid
    EXPECT_EQ(pointsOn(f, at(7, y), 1), all);
  }
}

TEST(PixelFootprint, APixelOnTwoSurfacesTakesTheMixOfTheirReflectancesNotItsOwnEstimate) {
  const recover::PixelFootprints f = footprintsOf(twoWalls(0.125f, 0.5625f));
  // The estimates as photo / (D + B) gives them: right on the whole pixels (0.2 left, 0.8 right),
  // wrong where the footprint mixes two surfaces' light (0.05: a dark floor's light divided by a
  // lit wall's), and at the top row, half of which sees nothing.
  std::vector<std::int32_t> object(std::size_t(kSize) * kSize);
  std::vector<glm::vec3> reflectance(object.size());
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const std::size_t p = at(x, y);
      object[p] = y == 0 ? -1 : x <= 4 ? 0 : 1;
      reflectance[p] = f.whole(p) && object[p] >= 0 ? glm::vec3(x <= 4 ? 0.2f : 0.8f) : glm::vec3(0.05f);
    }
  // The objects' means, what a surface with too few whole pixels nearby stands on: off on
  // purpose, so that the test sees which was used.
  const std::vector<glm::vec3> means = {glm::vec3(0.3f), glm::vec3(0.7f)};
  const std::size_t mixed = recover::mixFootprints(f, object, means, reflectance);
  EXPECT_EQ(mixed, std::size_t(6 + kSize)); // column 4 in rows 2-7, and all of row 1
  for (int y = 2; y < kSize; ++y) {
    EXPECT_NEAR(reflectance[at(4, y)].x, 0.5f, 1e-6f) << "row " << y; // half of 0.2, half of 0.8
    EXPECT_NEAR(reflectance[at(3, y)].x, 0.2f, 1e-6f);                // whole: its own estimate
    EXPECT_NEAR(reflectance[at(5, y)].x, 0.8f, 1e-6f);
  }
  // Row 1: a quarter of the footprint on the wall, the rest on nothing, which brings no light and
  // no reflectance: a quarter of the wall's.
  EXPECT_NEAR(reflectance[at(1, 1)].x, 0.25f * 0.2f, 1e-6f);
  EXPECT_NEAR(reflectance[at(6, 1)].x, 0.25f * 0.8f, 1e-6f);
  EXPECT_EQ(reflectance[at(1, 0)], glm::vec3(0.05f)); // its centre sees nothing: left alone

  // A surface none of whose pixels nearby is whole: its object's mean.
  const recover::PixelFootprints thin = footprintsOf(twoWalls(0.125f, 1.0f));
  std::vector<glm::vec3> noneWhole(object.size(), glm::vec3(0.05f));
  std::vector<std::int32_t> left(object.size(), 0);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      if (x != 4) noneWhole[at(x, y)] = glm::vec3(x < 4 ? 0.2f : 0.8f);
  recover::PixelFootprints narrow = thin;
  for (int y = 0; y < kSize; ++y)
    for (int x = 5; x < kSize; ++x) // the right wall's whole pixels hidden behind a third object
      for (int k = 0; k < recover::PixelFootprints::kPoints; ++k)
        narrow.object[at(x, y) * recover::PixelFootprints::kPoints + k] = 2;
  const std::vector<glm::vec3> threeMeans = {glm::vec3(0.3f), glm::vec3(0.7f), glm::vec3(0.9f)};
  recover::mixFootprints(narrow, left, threeMeans, noneWhole);
  EXPECT_NEAR(noneWhole[at(4, 4)].x, 0.5f * 0.2f + 0.5f * 0.7f, 1e-6f);
}

// The inverse, for the objects' means: a pixel half on the left wall (0.2) and half on the right
// (0.8) merged at their mix, 0.5, gives back its centre's own 0.2 at a quarter of its weight; a
// pixel with a quarter on its wall and the rest on nothing (no light, no reflectance) gives back
// 4 x its 0.05; whole pixels and those without an estimate are left alone; a centre object with
// less than kUnmixShare of the footprint (row 1's column 4: an eighth) loses its weight.
TEST(PixelFootprint, AMixedPixelUnmixedWithItsNeighboursMeansGivesItsOwnSurfacesReflectance) {
  const recover::PixelFootprints f = footprintsOf(twoWalls(0.125f, 0.5625f));
  std::vector<std::int32_t> object(std::size_t(kSize) * kSize);
  std::vector<glm::vec3> reflectance(object.size());
  std::vector<float> weight(object.size(), 2.0f);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const std::size_t p = at(x, y);
      object[p] = y == 0 ? -1 : x <= 4 ? 0 : 1;
      reflectance[p] = y <= 1 ? glm::vec3(0.05f) : f.whole(p) ? glm::vec3(x <= 4 ? 0.2f : 0.8f) : glm::vec3(0.5f);
    }
  weight[at(4, 7)] = 0.0f; // no estimate: left alone
  const std::vector<glm::vec3> means = {glm::vec3(0.2f), glm::vec3(0.8f)};
  const std::size_t unmixed = recover::unmixFootprints(f, object, means, reflectance, weight);
  EXPECT_EQ(unmixed, std::size_t(5 + kSize - 1)); // column 4 in rows 2-6, and row 1 but its column 4
  EXPECT_EQ(weight[at(4, 1)], 0.0f);
  for (int y = 2; y < 7; ++y) {
    EXPECT_NEAR(reflectance[at(4, y)].x, 0.2f, 1e-6f) << "row " << y; // (0.5 - 0.5 x 0.8) / 0.5
    EXPECT_FLOAT_EQ(weight[at(4, y)], 0.5f);                           // 2 x 0.5^2
    EXPECT_EQ(reflectance[at(3, y)], glm::vec3(0.2f));                 // whole: as it was
    EXPECT_FLOAT_EQ(weight[at(3, y)], 2.0f);
  }
  EXPECT_EQ(reflectance[at(4, 7)], glm::vec3(0.5f));
  EXPECT_NEAR(reflectance[at(1, 1)].x, 0.2f, 1e-6f); // 0.05 / 0.25: nothing adds no reflectance
  EXPECT_FLOAT_EQ(weight[at(1, 1)], 2.0f / 16.0f);
  EXPECT_EQ(reflectance[at(1, 0)], glm::vec3(0.05f)); // its centre sees nothing

  // A sliver: column 4 as the right wall's (an eighth of its footprint, the rest the left wall's):
  // no weight; unmixed, its estimate would be the noise of the other seven eighths times eight.
  const recover::PixelFootprints thin = footprintsOf(twoWalls(0.21875f, 1.0f));
  std::vector<std::int32_t> sliver(object.size(), 0);
  std::vector<float> sliverWeight(object.size(), 1.0f);
  std::vector<glm::vec3> sliverR(object.size(), glm::vec3(0.3f));
  for (int y = 0; y < kSize; ++y) sliver[at(4, y)] = 1;
  EXPECT_EQ(recover::unmixFootprints(thin, sliver, means, sliverR, sliverWeight), 0u);
  for (int y = 0; y < kSize; ++y) {
    EXPECT_EQ(pointsOn(thin, at(4, y), 1), recover::PixelFootprints::kPoints / 8) << "row " << y;
    EXPECT_EQ(sliverWeight[at(4, y)], 0.0f) << "row " << y;
    EXPECT_EQ(sliverWeight[at(3, y)], 1.0f) << "row " << y;
  }
}

} // namespace
} // namespace obscura::test
