// weighted_merge_test.cpp — the noise estimate, the error-weighted merge with indirect-only
// estimates, and the smoothing by noise, on small synthetic images with known answers.
#include "recover/weighted_merge.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace obscura::recover {
namespace {

// A w x h view of one flat wall facing the camera (object 0), or of two walls split at column
// `split` (objects 0 and 1, the same plane).
PixelGeometry wall(int w, int h, int split = -1) {
  PixelGeometry g;
  g.width = w;
  g.height = h;
  const std::size_t n = std::size_t(w) * h;
  g.position.assign(n, glm::vec3(0.0f));
  g.normal.assign(n, glm::vec3(0.0f, 0.0f, 1.0f));
  g.object.assign(n, 0);
  if (split >= 0)
    for (int y = 0; y < h; ++y)
      for (int x = split; x < w; ++x) g.object[std::size_t(y) * w + x] = 1;
  return g;
}

ConfidenceImage filled(int w, int h, float v) { return {w, h, std::vector<float>(std::size_t(w) * h, v)}; }

double spread(const std::vector<glm::vec3>& image, int channel) {
  double sum = 0.0, squares = 0.0;
  for (const auto& v : image) {
    sum += v[channel];
    squares += double(v[channel]) * v[channel];
  }
  const double n = double(image.size()), mean = sum / n;
  return std::sqrt(std::max(0.0, squares / n - mean * mean));
}

TEST(WeightedMerge, PhotoNoiseEstimatesAFlatSurfacesVariance) {
  const int w = 64, h = 64;
  const PixelGeometry g = wall(w, h);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  std::vector<glm::vec3> photo(std::size_t(w) * h);
  for (auto& c : photo) c = glm::vec3(1.0f + noise(rng));
  const std::vector<float> variance = photoNoise(photo, g);
  double mean = 0.0;
  for (float v : variance) mean += v;
  mean /= double(variance.size());
  // sigma^2 = 0.0025; the estimate averages ~25 residuals a pixel, and 4096 pixels here.
  EXPECT_NEAR(mean, 0.0025, 0.0025 * 0.1);
}

TEST(WeightedMerge, PhotoNoiseDoesNotCountAStepBetweenSurfacesAsNoise) {
  const int w = 16, h = 8;
  const PixelGeometry g = wall(w, h, 8);
  std::vector<glm::vec3> photo(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) photo[std::size_t(y) * w + x] = glm::vec3(x < 8 ? 0.2f : 2.0f);
  for (float v : photoNoise(photo, g)) EXPECT_EQ(v, 0.0f);
}

TEST(WeightedMerge, LitEstimatesOutweighIndirectOnlyOnesAndShadowedPixelsAreRecovered) {
  // Two shots of a 12 x 12 wall of reflectance 0.5 (grey), noise free. Shot 0 lights the left
  // half (D = 1, B = 0.2), shot 1 the right half (D = 2, B = 0.3); the other half of each is in
  // that lamp's shadow (D = 0). A column in the middle sits in the penumbra of neither.
  const int w = 12, h = 12;
  const PixelGeometry g = wall(w, h);
  const std::size_t n = std::size_t(w) * h;
  std::vector<std::vector<glm::vec3>> photos(2, std::vector<glm::vec3>(n)), direct(2, std::vector<glm::vec3>(n)),
      indirect(2, std::vector<glm::vec3>(n)), estimates(2, std::vector<glm::vec3>(n));
  std::vector<ConfidenceImage> visibility{filled(w, h, 0.0f), filled(w, h, 0.0f)};
  const float rho = 0.5f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      const bool left = x < 6;
      direct[0][p] = glm::vec3(left ? 1.0f : 0.0f);
      direct[1][p] = glm::vec3(left ? 0.0f : 2.0f);
      indirect[0][p] = glm::vec3(0.2f);
      indirect[1][p] = glm::vec3(0.3f);
      visibility[0].k[p] = left ? 1.0f : 0.0f;
      visibility[1].k[p] = left ? 0.0f : 1.0f;
      for (int i = 0; i < 2; ++i) {
        photos[i][p] = rho * (direct[i][p] + indirect[i][p]);
        estimates[i][p] = photos[i][p] / (direct[i][p] + indirect[i][p]);
      }
    }
  // The paper's confidences: the lit side, less a shadow edge's two columns.
  std::vector<ConfidenceImage> confidences = visibility;
  for (int y = 0; y < h; ++y)
    for (int x = 4; x < 8; ++x)
      for (auto& k : confidences) k.k[std::size_t(y) * w + x] = 0.0f;
  WeightedMergeOptions options;
  options.smoothingRadius = 0;
  const WeightedMerge m = weightedMerge(photos, direct, indirect, estimates, confidences, visibility, g, options);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      // Everywhere but the two columns each side of the edge (lit by one shot, its shadow window
      // not clear in the other) the pixel is recovered: the reflectance exactly.
      const bool edge = x >= 4 && x < 8;
      if (edge) {
        EXPECT_EQ(m.relativeVariance[p], 0.0f) << x << "," << y;
        continue;
      }
      EXPECT_NEAR(m.reflectance[p].x, rho, 1e-5f) << x << "," << y;
      // One lit estimate and one indirect-only one: the other lamp's 5x5 window is all shadow
      // two columns past the edge.
      EXPECT_EQ(m.directConfidence[p], 1.0f);
      EXPECT_EQ(m.indirectShots[p], 1.0f) << x;
      const int lit = x < 6 ? 0 : 1, dark = 1 - lit;
      // v = (sigma / C)^2 + (e_B B / (D + B))^2: B's share is 1 in the shadow, 1/6 or less lit
      // (the photo's own "noise" near the step between light and shadow lowers both).
      EXPECT_GT(m.weights[lit][p], 20.0f * m.weights[dark][p]) << x;
    }
}

TEST(WeightedMerge, APixelInEveryLampsShadowIsRecoveredFromItsIndirectLightAlone) {
  const int w = 7, h = 7;
  const PixelGeometry g = wall(w, h);
  const std::size_t n = std::size_t(w) * h;
  const float rho = 0.8f;
  std::vector<std::vector<glm::vec3>> photos(3, std::vector<glm::vec3>(n)), direct(3, std::vector<glm::vec3>(n, glm::vec3(0.0f))),
      indirect(3, std::vector<glm::vec3>(n)), estimates(3, std::vector<glm::vec3>(n));
  for (int i = 0; i < 3; ++i)
    for (std::size_t p = 0; p < n; ++p) {
      indirect[i][p] = glm::vec3(0.1f * float(i + 1), 0.05f, 0.2f);
      photos[i][p] = rho * indirect[i][p];
      estimates[i][p] = photos[i][p] / indirect[i][p];
    }
  const std::vector<ConfidenceImage> none(3, filled(w, h, 0.0f));
  const WeightedMerge m = weightedMerge(photos, direct, indirect, estimates, none, none, g, WeightedMergeOptions{});
  for (std::size_t p = 0; p < n; ++p) {
    EXPECT_NEAR(m.reflectance[p].x, rho, 1e-5f);
    EXPECT_NEAR(m.reflectance[p].z, rho, 1e-5f);
    EXPECT_EQ(m.indirectShots[p], 3.0f);
    EXPECT_EQ(m.directConfidence[p], 0.0f);
    // Three estimates, each of relative variance e_B^2 (+ the floor): a third of it.
    const float eB = WeightedMergeOptions{}.indirectUncertainty;
    EXPECT_NEAR(m.relativeVariance[p], eB * eB / 3.0f, 1e-5f);
  }
}

TEST(WeightedMerge, SmoothingByNoiseFlattensAWallAndKeepsATextureEdge) {
  // A wall whose left half has reflectance 0.3 and right half 0.6 (a texture edge inside one
  // object), with 5 % relative noise per pixel, and that variance known.
  const int w = 40, h = 40;
  const PixelGeometry g = wall(w, h);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  std::vector<glm::vec3> r(std::size_t(w) * h);
  std::vector<float> variance(r.size(), 0.05f * 0.05f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) r[std::size_t(y) * w + x] = glm::vec3(x < 20 ? 0.3f : 0.6f) * (1.0f + noise(rng));
  const std::vector<glm::vec3> out = smoothByNoise(r, variance, g, 3, 2.5f);
  std::vector<glm::vec3> leftIn, leftOut, rightOut;
  for (int y = 4; y < h - 4; ++y)
    for (int x = 4; x < 16; ++x) {
      leftIn.push_back(r[std::size_t(y) * w + x]);
      leftOut.push_back(out[std::size_t(y) * w + x]);
    }
  // 49 pixels pool in the interior: the spread falls by about 7 (the 2.5 sigma window keeps ~99 %).
  EXPECT_LT(spread(leftOut, 0), spread(leftIn, 0) / 4.0);
  // The edge stays sharp: the columns next to it keep their own side's level.
  for (int y = 0; y < h; ++y) {
    EXPECT_NEAR(out[std::size_t(y) * w + 19].x, 0.3f, 0.3f * 0.05f) << y;
    EXPECT_NEAR(out[std::size_t(y) * w + 20].x, 0.6f, 0.6f * 0.05f) << y;
  }
}

} // namespace
} // namespace obscura::recover
