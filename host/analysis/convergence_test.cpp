#include "analysis/convergence.h"

#include <cmath>

#include <gtest/gtest.h>

namespace obscura::analysis {
namespace {

Curve monteCarloCurve() {
  // RMSE = 1 / sqrt(t): an unbiased estimator.
  Curve c{.method = "pt", .points = {}};
  for (double t : {1.0, 4.0, 16.0, 64.0})
    c.points.push_back({.spp = 1, .raysPerPixel = 1, .gpuMs = t,
                        .noise = {.rmse = 1.0 / std::sqrt(t), .mae = 0.5 / std::sqrt(t)},
                        .total = {.rmse = 1.0 / std::sqrt(t)}});
  return c;
}

TEST(Convergence, InterpolatesInLogLog) {
  TimeAt t = timeToReach(monteCarloCurve(), 1.0 / std::sqrt(8.0), ErrorKind::Noise);
  ASSERT_TRUE(t.valid);
  EXPECT_FALSE(t.extrapolated);
  EXPECT_NEAR(t.ms, 8.0, 1e-9);
  // The same curve read in another measure.
  EXPECT_NEAR(timeToReach(monteCarloCurve(), 0.5 / std::sqrt(8.0), ErrorKind::Noise, Metric::Mae).ms, 8.0, 1e-9);
}

TEST(Convergence, ExtrapolatesAtTheMonteCarloRate) {
  TimeAt t = timeToReach(monteCarloCurve(), 1.0 / 32.0, ErrorKind::AgainstReference);
  ASSERT_TRUE(t.valid);
  EXPECT_TRUE(t.extrapolated);
  EXPECT_NEAR(t.ms, 1024.0, 1e-6);
  EXPECT_NEAR(timeToReach(monteCarloCurve(), 2.0, ErrorKind::Noise).ms, 1.0, 1e-12); // already there
  EXPECT_FALSE(timeToReach(Curve{}, 1.0, ErrorKind::Noise).valid);
}

TEST(Convergence, ErrorAtATimeInterpolatesAndExtendsAtTheMonteCarloRate) {
  const Curve c = monteCarloCurve();
  const ErrorAt inside = errorAtTime(c, 8.0, ErrorKind::Noise);
  ASSERT_TRUE(inside.valid);
  EXPECT_FALSE(inside.extrapolated);
  EXPECT_NEAR(inside.error, 1.0 / std::sqrt(8.0), 1e-12);
  EXPECT_NEAR(errorAtTime(c, 8.0, ErrorKind::Noise, Metric::Mae).error, 0.5 / std::sqrt(8.0), 1e-12);
  EXPECT_NEAR(errorAtTime(c, 16.0, ErrorKind::Noise).error, 0.25, 1e-12); // on a point
  const ErrorAt before = errorAtTime(c, 0.25, ErrorKind::Noise), after = errorAtTime(c, 256.0, ErrorKind::Noise);
  EXPECT_TRUE(before.extrapolated && after.extrapolated);
  EXPECT_NEAR(before.error, 2.0, 1e-12);
  EXPECT_NEAR(after.error, 1.0 / 16.0, 1e-12);
  EXPECT_FALSE(errorAtTime(Curve{}, 1.0, ErrorKind::Noise).valid);
}

} // namespace
} // namespace obscura::analysis
