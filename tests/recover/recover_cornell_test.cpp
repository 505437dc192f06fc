// recover_cornell_test.cpp — reflectance recovery [IVR §4] on photographs nobody here rendered:
// six Blender Cycles renders of the Cornell box, one lamp each (shared/photos/cornell-box), with
// the true reflectance (albedo.exr) as the answer key. RMSE per light region (recovery_accuracy.h).
//
// Measured at these settings (lavapipe, spp 4, 16 gather rays, 3 hidden bounces, the weighted
// merge, seed 1; docs/BENCHMARKS.md):
//   gather      lit 0.0122  penumbra 0.046  shadow 0.0064  all 0.0199
//   the first design (paper's merge, hidden surfaces at the mean B, 64 rays)  lit 0.0169  all 0.0241
//   constant    lit 0.132                                  all 0.140
// The goals (lit <= 0.02, all <= 0.04) are asserted as such.
#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "recover_cornell_fixture.h"

namespace obscura::test {
namespace {
using namespace obscura::recover;

TEST_F(RecoverCornell, GatheredIndirectLightMeetsTheGoalsAndConverges) {
  const Recovery& r = standardRecovery();
  const RecoveryAccuracy a = accuracy(r);
  EXPECT_LE(a.lit.rmse, 0.02) << "lit pixels";
  EXPECT_LE(a.all.rmse, 0.04) << "all pixels";
  EXPECT_LE(a.shadow.rmse, 0.04) << "shadow (filled) pixels";
  EXPECT_GT(a.lit.pixels, a.all.pixels / 2); // most of the image is lit by some lamp
  // The iteration converges: each RMS change at most a third of the one before until it is
  // below 1e-4 (measured 0.181, 0.0162, 0.0011, 0.00004, 0, 0), the last below 0.005.
  ASSERT_EQ(r.iterations.size(), 7u);
  for (std::size_t i = 2; i < r.iterations.size(); ++i)
    EXPECT_LE(r.iterations[i].rmsChange, std::max(r.iterations[i - 1].rmsChange / 3.0, 1e-4)) << "iteration " << i;
  EXPECT_LT(r.iterations.back().rmsChange, 0.005);
  // The white objects' means come out white (0.725, 0.71, 0.68) to 3 %, the red wall red.
  for (std::size_t o = 0; o < r.objectNames.size(); ++o) {
    if (r.objectNames[o] == "cube_1" || r.objectNames[o] == "rectangle_1") {
      EXPECT_NEAR(r.iterations.back().objectReflectance[o].x, 0.725f, 0.02f) << r.objectNames[o];
    }
  }
}

TEST_F(RecoverCornell, GatheredIndirectLightBeatsThePapersConstantAmbient) {
  RecoveryOptions constant = options();
  constant.indirect = IndirectModel::Constant;
  const RecoveryAccuracy c = accuracy(recover(constant, *photos_));
  const RecoveryAccuracy g = accuracy(standardRecovery());
  EXPECT_LT(g.lit.rmse, 0.5 * c.lit.rmse);
  EXPECT_LT(g.all.rmse, 0.5 * c.all.rmse);
}

TEST_F(RecoverCornell, PathsThroughHiddenSurfacesAndTheWeightedMergeLowerTheFirstDesignsError) {
  RecoveryOptions first = options();
  first.merge = MergeModel::Paper;
  first.hiddenBounces = 0;
  first.gatherRays = 64;
  first.iterations = 3;
  const RecoveryAccuracy before = accuracy(recover(first, *photos_));
  const RecoveryAccuracy after = accuracy(standardRecovery());
  // Measured 0.0169 -> 0.0122 (lit), 0.0241 -> 0.0199 (all) at 16 gather rays (0.0091 and
  // 0.0169 at 32 rays and spp 16).
  EXPECT_LT(after.lit.rmse, 0.8 * before.lit.rmse);
  EXPECT_LT(after.all.rmse, 0.9 * before.all.rmse);
}

TEST_F(RecoverCornell, MinFilterKeepsShadowedEstimatesOutOfTheMerge) {
  // Without the 5x5 min filter the smoothing filters spread confidence into pixels no lamp
  // lights, whose estimates C / B are noisy (measured all 0.0422 against 0.0288; one iteration at 8
  // gather rays, 2 s less, 0.0510 against 0.0399: too near the bound).
  // The paper's merge: the weighted one gives an estimate near a shadow edge a weight by its
  // error instead (without the min filter it measured all 0.0179 against 0.0203 with it).
  RecoveryOptions paper = options();
  paper.merge = MergeModel::Paper;
  paper.iterations = 3; // converged (RMS change 0.0005 at the third; the standard recovery's test)
  RecoveryOptions noMin = paper;
  noMin.filters.minFilter = false;
  const RecoveryAccuracy without = accuracy(recover(noMin, *photos_));
  const RecoveryAccuracy with = accuracy(recover(paper, *photos_));
  std::printf("all pixels' RMSE: %.4f without the min filter, %.4f with it\n", without.all.rmse, with.all.rmse);
  EXPECT_LT(with.all.rmse, 0.8 * without.all.rmse);
}

TEST_F(RecoverCornell, OutlierTestRemovesALampFixtureSeenInOnePhoto) {
  // The paper's reason for the outlier test: the lamp's fixture (or a highlight) in one photo.
  // Shot 0 gets a bright 12x12 patch on the back wall; the other photos agree there.
  PhotoSet photos = *photos_;
  const int x0 = 150, y0 = 60;
  std::vector<std::size_t> patch;
  for (int y = y0; y < y0 + 12; ++y)
    for (int x = x0; x < x0 + 12; ++x) {
      const std::size_t p = std::size_t(y) * photos.width + x;
      photos.shots[0].radiance[p] = glm::vec3(5.0f);
      patch.push_back(p);
    }
  // One iteration each, 1 spp and 4 gather rays: the fixture is in the photographs, not in the
  // indirect light the iterations and the gather refine (measured, seed 1: the paper's merge 2.24
  // without the outlier test, 0.017 with it, the weighted merge 0.011; at options() and one
  // iteration 0.0125 and 0.0057, for 3 s more).
  const auto cheap = [] {
    RecoveryOptions o = options();
    o.iterations = 1;
    o.spp = 1;
    o.gatherRays = 4;
    return o;
  };
  auto patchError = [&](const Recovery& r) {
    double sum = 0.0;
    for (std::size_t p : patch) {
      const glm::vec3 d = r.reflectance[p] - (*truth_)[p];
      sum += glm::dot(d, d) / 3.0;
    }
    return std::sqrt(sum / double(patch.size()));
  };
  // The paper's merge: the outlier test is what removes the fixture.
  RecoveryOptions paper = cheap();
  paper.merge = MergeModel::Paper;
  RecoveryOptions noOutlier = paper;
  noOutlier.filters.outlier = false;
  const double without = patchError(recover(noOutlier, photos));
  const double with = patchError(recover(paper, photos));
  EXPECT_GT(without, 0.3); // the fixture shows
  EXPECT_LT(with, 0.05);   // the fixture is gone
  // The weighted merge removes it without the outlier test too: the fixture's estimates
  // (R ~ 5 / light) are above 1, which no diffuse surface reflects.
  RecoveryOptions weightedOnly = cheap();
  weightedOnly.filters.outlier = false;
  const double weighted = patchError(recover(weightedOnly, photos));
  std::printf("the patch's RMSE: the paper's merge %.4f without the outlier test, %.4f with it; the weighted merge "
              "without it %.4f\n", without, with, weighted);
  EXPECT_LT(weighted, 0.05);
}

} // namespace
} // namespace obscura::test
