// recover_classroom_test.cpp — reflectance recovery on a larger room than the Cornell box: six
// Blender Cycles photographs of shared/scenes/classroom (tests/data/photos/classroom, made by
// tools/cycles_photo_set.py), where 78 % of the gather's rays meet surfaces the camera does not
// see, chairs and desks are a few pixels wide and a quarter of the pixels no lamp lights.
//
// Measured at the defaults (spp 8, 16 gather rays from 4 points of each pixel, 3 hidden bounces cut
// per object, confidences filtered along surfaces, the weighted merge with each photograph's noise
// measured without its texture and each shot weighed by its indirect light's longer paths, the
// kept merge smoothed over a 65 x 65 window across each plain object's faces and a textured
// object's within its photographs' noise, clamped at 1 after that, the footprints' mix on 8 x 8
// points near edges, the object means from the mixed pixels unmixed, the cut per region of what
// the camera sees, the pixels the filters emptied on a plain object at its mean, else filled from
// their surface's whole pixels nearby; seeds 1, 2, 3) on the photographs rendered at 16 bounces
// (docs/BENCHMARKS.md "Recovery: the cut's regions over what the camera sees"):
//   lit 0.0048 / 0.0052 / 0.0048   lit in some photo 0.0179 / 0.0178 / 0.0173   all 0.0185 / 0.0223 / 0.0179
//   shadow (no lamp lights the pixel) 0.0223 / 0.0429 / 0.0222
// (The regions over the model's bounds, 221 m of ground: lit in some photo 0.0200 / 0.0205 /
// 0.0199; and with the emptied pixels from their raw estimates by visibility, 0.0226 at seed 1.
// With the object means from the mixed pixels as they are: all 0.0312 / 0.0339 / 0.0324, lit in
// some photo 0.0281 / 0.0287 / 0.0277; with the footprints at 4 x 4 points before that, all
// 0.0332 / 0.0355 / 0.0344.)
// Before the wide smoothing (a 7 x 7 window on one face), seed 1: lit 0.0172, lit in some photo
// 0.0444, all 0.0499, shadow 0.0799; before the footprints' mix 0.0573 / 0.0625 (all).
// The bounds below are the largest of the three plus 10 %, several times the seed-to-seed spread;
// issue 36's goals are all 0.04 and lit in some photo 0.02 (both met). On the 6-bounce
// photographs, with the gather's rays from each pixel's mean point, all was 0.0968 and lit 0.0361
// (a chair's tubular frame: the point inside the tube); cut with the pixels' mean B the shadow
// pixels came out at 0.1396; with the seen objects' mean colour for every unseen object, at
// 0.117. These fail here. Filtered in image windows, 6,829 pixels (chairs'
// frames beside their shadows) were filled from visibility; along surfaces 927-967.
#include <cmath>

#include <gtest/gtest.h>

#include "app/scene_setup.h"
#include "gpu_test.h"
#include "recover/photo_set.h"
#include "recover/recovery_accuracy.h"
#include "recover/reflectance_recovery.h"

namespace obscura::test {
namespace {
using namespace obscura::recover;

class RecoverClassroom : public GpuTest {};

TEST_F(RecoverClassroom, ALargerRoomIsRecoveredToItsMeasuredAccuracyWithEveryReflectanceInRange) {
  const app::LoadedScene room = app::loadScene(sharedScene("classroom/classroom.gltf"));
  const PhotoSet photos = readPhotoSet(repoPath("tests/data/photos/classroom/lights.json"));
  int w = 0, h = 0;
  const std::vector<glm::vec3> truth = readRadiance(repoPath("tests/data/photos/classroom/albedo.exr"), 1.0f, w, h);
  ASSERT_EQ(w, photos.width);
  ASSERT_EQ(h, photos.height);
  const Recovery r =
      recoverReflectance(context(), room.scene, room.bvh, room.scene.cameras.at(0), photos, RecoveryOptions{});
  const RecoveryAccuracy a = recoveryAccuracy(r.reflectance, truth, lightRegions(r.visibility, r.object));
  EXPECT_LE(a.lit.rmse, 0.0057);
  EXPECT_LE(a.direct.rmse, 0.0197);
  EXPECT_LE(a.all.rmse, 0.0245);
  EXPECT_LE(a.shadow.rmse, 0.0472);
  // The iteration settles instead of swinging between high and low object means.
  EXPECT_LT(r.iterations.back().rmsChange, 0.01);
  // A quarter of the pixels no lamp lights; the merge recovers some of them from their indirect
  // light (measured 2,516-2,562), and the fills are counted: of the pixels the filters left that
  // some lamp lights, about half from their surface's whole pixels nearby (measured 407-431), the
  // others on a plain object at its mean, and only those of objects too small to judge from
  // visibility (measured 18-21; 458-472 before the plain objects took their mean).
  EXPECT_GT(r.indirectOnlyPixels, 2000u);
  EXPECT_GT(r.filledFromSurface, 300u);
  EXPECT_LT(r.filledFromVisibility, 100u);
  EXPECT_EQ(r.litPixels + r.indirectOnlyPixels + r.filledFromSurface + r.filledFromVisibility + r.filledFromObject,
            a.all.pixels);
  // Every reflectance is a reflectance: finite, in [0, 1] (the first design had 24 pixels at 3 to 45).
  for (const glm::vec3& v : r.reflectance) {
    ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
    ASSERT_GE(std::min({v.x, v.y, v.z}), 0.0f);
    ASSERT_LE(std::max({v.x, v.y, v.z}), 1.0f);
  }
  // The largest object (walls and ceiling, 43 % of the surface pixels): its mean within 2 % of
  // the truth's (issue 36's goal for large flat surfaces; measured 1.001, 0.997 before the merge's
  // noise without texture and weights by the longer paths; 0.994 on the 6-bounce photographs;
  // 0.986 with the gather from the pixels' mean points).
  std::vector<std::size_t> count(room.scene.objects.size(), 0);
  for (std::int32_t o : r.object)
    if (o >= 0) ++count[static_cast<std::size_t>(o)];
  const auto walls = static_cast<std::int32_t>(std::max_element(count.begin(), count.end()) - count.begin());
  double recovered = 0.0, expected = 0.0;
  for (std::size_t p = 0; p < r.object.size(); ++p)
    if (r.object[p] == walls) {
      recovered += r.reflectance[p].x + r.reflectance[p].y + r.reflectance[p].z;
      expected += truth[p].x + truth[p].y + truth[p].z;
    }
  EXPECT_NEAR(recovered / expected, 1.0, 0.02);
}

} // namespace
} // namespace obscura::test
