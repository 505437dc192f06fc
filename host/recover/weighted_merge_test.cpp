// weighted_merge_test.cpp — the noise estimate, the error-weighted merge with indirect-only
// estimates, and the smoothing by noise, on small synthetic images with known answers.
#include "recover/weighted_merge.h"

#include <algorithm>
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

// Three photographs of a wallpapered wall: reflectance 0.3 / 0.8 in 2 x 2 pixel checks, each
// shot lit smoothly (a gradient across the wall, brighter by shot), 3 % relative noise.
struct Wallpaper {
  static constexpr int w = 48, h = 48;
  static constexpr float noise = 0.03f;
  PixelGeometry geometry = wall(w, h);
  std::vector<float> reflectance;
  std::vector<std::vector<glm::vec3>> photos, light;

  Wallpaper() {
    const std::size_t n = std::size_t(w) * h;
    std::mt19937 rng(11);
    std::normal_distribution<float> gauss(0.0f, noise);
    reflectance.resize(n);
    photos.assign(3, std::vector<glm::vec3>(n));
    light.assign(3, std::vector<glm::vec3>(n));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t p = std::size_t(y) * w + x;
        reflectance[p] = ((x / 2 + y / 2) % 2) == 0 ? 0.3f : 0.8f;
        for (int i = 0; i < 3; ++i) {
          light[i][p] = glm::vec3(float(i + 1) * (1.0f + 0.01f * float(x) + 0.005f * float(i * y)));
          photos[i][p] = reflectance[p] * light[i][p] * (1.0f + gauss(rng));
        }
      }
  }
  bool interior(int x, int y) const { return x >= 3 && x < w - 3 && y >= 3 && y < h - 3; }
};

TEST(WeightedMerge, ShotNoiseTakesAWallpapersPatternOutOfThePhotographsNoise) {
  const Wallpaper wall;
  for (std::size_t i = 0; i < wall.photos.size(); ++i) {
    const std::vector<float> alone = photoNoise(wall.photos[i], wall.geometry);
    const std::vector<float> shot = shotNoise(wall.photos, i, wall.geometry);
    double aloneSum = 0.0, shotSum = 0.0;
    int n = 0;
    for (int y = 0; y < wall.h; ++y)
      for (int x = 0; x < wall.w; ++x) {
        if (!wall.interior(x, y)) continue;
        const std::size_t p = std::size_t(y) * wall.w + x;
        const double c = wall.photos[i][p].x;
        aloneSum += alone[p] / (c * c);
        shotSum += shot[p] / (c * c);
        ++n;
      }
    const double truth = double(Wallpaper::noise) * Wallpaper::noise;
    // The photograph alone counts the checks' contrast as noise: ~400 times the truth here. Over
    // the other shots' sum the checks cancel; that sum's own noise (two shots: half a shot's
    // variance) adds about half: 1.5-1.8 times the truth.
    EXPECT_GT(aloneSum / n, 20.0 * truth) << i;
    EXPECT_GT(shotSum / n, 0.8 * truth) << i;
    EXPECT_LT(shotSum / n, 2.0 * truth) << i;
  }
}

TEST(WeightedMerge, TheMergeKeepsAWallpapersPatternAndAveragesItsNoise) {
  const Wallpaper wall;
  const std::size_t n = wall.reflectance.size();
  std::vector<std::vector<glm::vec3>> indirect(3, std::vector<glm::vec3>(n, glm::vec3(0.0f))), estimates = wall.photos;
  for (int i = 0; i < 3; ++i)
    for (std::size_t p = 0; p < n; ++p) estimates[i][p] /= wall.light[i][p]; // R_i = C_i / D_i
  const std::vector<ConfidenceImage> lit(3, filled(Wallpaper::w, Wallpaper::h, 1.0f));
  const WeightedMerge m = weightedMerge(wall.photos, wall.light, indirect, estimates, lit, lit, wall.geometry,
                                        WeightedMergeOptions{});
  double squares = 0.0;
  int count = 0;
  for (int y = 0; y < Wallpaper::h; ++y)
    for (int x = 0; x < Wallpaper::w; ++x) {
      if (!wall.interior(x, y)) continue;
      const std::size_t p = std::size_t(y) * Wallpaper::w + x;
      const double e = m.reflectance[p].x / wall.reflectance[p] - 1.0;
      squares += e * e;
      ++count;
    }
  // Three shots merge to 3 % / sqrt 3 = 1.7 %, and the smoothing pools the pixels of the same
  // level in the 7 x 7 window (about half of its 49) to 0.4 % (measured). With the photograph's
  // own spread as its noise the smoothing pooled both levels: 44 % off.
  EXPECT_LT(std::sqrt(squares / count), 0.01);
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

TEST(WeightedMerge, AShotWhoseLightComesTheLongWayRoundWeighsLess) {
  // Two shots of a wall in both lamps' shadow: shot 0's indirect light comes a fifth through the
  // gather's longer paths (m = 0.2) and gives 0.5, shot 1's all of it (m = 1) and gives 0.8.
  // Noise-free photographs: the weights are 1 / (e_B m)^2 (+ the floor), 25 : 1.
  const int w = 9, h = 9;
  const PixelGeometry g = wall(w, h);
  const std::size_t n = std::size_t(w) * h;
  std::vector<std::vector<glm::vec3>> photos(2, std::vector<glm::vec3>(n)),
      direct(2, std::vector<glm::vec3>(n, glm::vec3(0.0f))), indirect(2, std::vector<glm::vec3>(n, glm::vec3(0.1f))),
      estimates(2);
  for (std::size_t p = 0; p < n; ++p) {
    photos[0][p] = glm::vec3(0.05f);
    photos[1][p] = glm::vec3(0.08f);
  }
  for (int i = 0; i < 2; ++i) {
    estimates[i] = photos[i];
    for (auto& r : estimates[i]) r /= 0.1f;
  }
  const std::vector<std::vector<float>> modelled{std::vector<float>(n, 0.2f), std::vector<float>(n, 1.0f)};
  const std::vector<ConfidenceImage> none(2, filled(w, h, 0.0f));
  WeightedMergeOptions options;
  options.smoothingRadius = 0;
  const WeightedMerge m = weightedMerge(photos, direct, indirect, estimates, none, none, g, options, &modelled);
  const WeightedMerge alike = weightedMerge(photos, direct, indirect, estimates, none, none, g, options);
  const float eB2 = options.indirectUncertainty * options.indirectUncertainty;
  const float w0 = 1.0f / (eB2 * 0.04f + 1e-6f), w1 = 1.0f / (eB2 + 1e-6f);
  for (std::size_t p = 0; p < n; ++p) {
    EXPECT_NEAR(m.reflectance[p].x, (0.5f * w0 + 0.8f * w1) / (w0 + w1), 1e-4f);
    EXPECT_NEAR(alike.reflectance[p].x, 0.65f, 1e-4f); // without m, the plain mean
  }
}

TEST(WeightedMerge, AnUnmergedPixelIsFilledFromTheMergedPixelsOfItsOwnSurfaceNearby) {
  // Two walls side by side (objects 0 and 1, split at column 6), merged to 0.2 and 0.9, with a
  // hole of unmerged pixels on wall 0 along the split; the merged pixels' variances differ.
  const int w = 12, h = 12;
  const PixelGeometry g = wall(w, h, 6);
  WeightedMerge m;
  m.reflectance.assign(std::size_t(w) * h, glm::vec3(0.0f));
  m.relativeVariance.assign(m.reflectance.size(), 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      if (x >= 4 && x < 6) continue; // the hole, beside the other wall
      // Wall 0: 0.2 at variance 0.01 in even rows, 0.3 at 0.04 in odd ones (weights 4 : 1).
      m.reflectance[p] = glm::vec3(x < 6 ? (y % 2 == 0 ? 0.2f : 0.3f) : 0.9f);
      m.relativeVariance[p] = x < 6 && y % 2 == 1 ? 0.04f : 0.01f;
    }
  for (int y = 0; y < h; ++y) {
    const auto filled = surfaceFill(m, g, std::size_t(y) * w + 5);
    ASSERT_TRUE(filled) << y;
    // Only wall 0's pixels (columns 2-3 of the 7 x 7 window) count, never wall 1's 0.9; the
    // weighted mean of 0.2 and 0.3 lies between 0.2 and the plain mean 0.25.
    EXPECT_GT(filled->x, 0.2f) << y;
    EXPECT_LT(filled->x, 0.25f) << y;
  }
  // A pixel with fewer than kSurfaceFillSupport merged pixels of its surface nearby gets none.
  WeightedMerge lone = m;
  std::fill(lone.relativeVariance.begin(), lone.relativeVariance.end(), 0.0f);
  lone.relativeVariance[0] = lone.relativeVariance[1] = 0.01f;
  EXPECT_FALSE(surfaceFill(lone, g, std::size_t(1) * w + 1));
  // With the footprints: wall 0's column 3, beside the hole, merged to 0.6 (its pixels' footprints
  // cross onto the other wall, their estimates a mix), is left out; only the whole pixels of
  // column 2 fill, so the fill is between 0.2 and 0.25 as before, not pulled towards 0.6.
  WeightedMerge edged = m;
  std::vector<bool> whole(m.reflectance.size(), true);
  for (int y = 0; y < h; ++y) {
    edged.reflectance[std::size_t(y) * w + 3] = glm::vec3(0.6f);
    whole[std::size_t(y) * w + 3] = false;
  }
  for (int y = 1; y < h - 1; ++y) {
    const std::size_t p = std::size_t(y) * w + 5;
    const auto kept = surfaceFill(edged, g, p, &whole), mixed = surfaceFill(edged, g, p);
    ASSERT_TRUE(kept && mixed) << y;
    EXPECT_GT(kept->x, 0.2f) << y;
    EXPECT_LT(kept->x, 0.25f) << y;
    EXPECT_GT(mixed->x, 0.3f) << y; // the edge column's 0.6 weighs in without them
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

TEST(WeightedMerge, TheSmoothingKeepsAnIndirectlyLitTextureAndFlattensAPlainWallBesideIt) {
  // Two walls side by side (objects 0 and 1), lit only indirectly in three shots (D = 0, V = 0:
  // every estimate is indirect-only, its tolerance in the smoothing wide with B's error): the left
  // a granite (each pixel's reflectance uniform in [0.4, 0.8]), the right plain 0.6; 3 % noise.
  const int w = 40, h = 40, split = 20, shots = 3;
  const PixelGeometry g = wall(w, h, split);
  const std::size_t n = std::size_t(w) * h;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> granite(0.4f, 0.8f);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  std::vector<float> truth(n);
  std::vector<std::vector<glm::vec3>> photos(shots, std::vector<glm::vec3>(n)), direct(shots, std::vector<glm::vec3>(n, glm::vec3(0.0f))),
      indirect(shots, std::vector<glm::vec3>(n)), estimates(shots, std::vector<glm::vec3>(n));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      truth[p] = x < split ? granite(rng) : 0.6f;
      for (int i = 0; i < shots; ++i) {
        indirect[i][p] = glm::vec3(0.2f * float(i + 1) * (1.0f + 0.01f * float(x)));
        photos[i][p] = truth[p] * indirect[i][p] * (1.0f + noise(rng));
        estimates[i][p] = photos[i][p] / indirect[i][p];
      }
    }
  const std::vector<ConfidenceImage> none(shots, filled(w, h, 0.0f));
  const WeightedMerge m = weightedMerge(photos, direct, indirect, estimates, none, none, g, WeightedMergeOptions{});
  ASSERT_EQ(m.objectTextures.size(), 2u);
  EXPECT_EQ(m.objectTextures[0], SurfaceTexture::Textured);
  EXPECT_NE(m.objectTextures[1], SurfaceTexture::Textured);
  // The same merge smoothed as before objects were judged: every estimate's tolerance is ~50 %,
  // so the granite's levels pool.
  WeightedMergeOptions unsmoothed;
  unsmoothed.smoothingRadius = 0;
  const WeightedMerge raw = weightedMerge(photos, direct, indirect, estimates, none, none, g, unsmoothed);
  const std::vector<glm::vec3> pooled = smoothByNoise(raw.reflectance, raw.relativeVariance, g, 3, 2.5f);
  double kept = 0.0, blurred = 0.0;
  int count = 0;
  std::vector<glm::vec3> plainIn, plainOut;
  for (int y = 3; y < h - 3; ++y)
    for (int x = 3; x < w - 3; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      if (x < split - 3) {
        kept += std::pow(m.reflectance[p].x / truth[p] - 1.0, 2);
        blurred += std::pow(pooled[p].x / truth[p] - 1.0, 2);
        ++count;
      } else if (x > split + 3) {
        plainIn.push_back(raw.reflectance[p]);
        plainOut.push_back(m.reflectance[p]);
      }
    }
  // Three shots merge the noise to 3 % / sqrt 3 = 1.7 %, and the granite is smoothed only within
  // that (measured: 1.6 %); pooled within B's error, it is near its window's mean.
  EXPECT_LT(std::sqrt(kept / count), 0.025);
  EXPECT_GT(std::sqrt(blurred / count), 0.08);
  EXPECT_LT(spread(plainOut, 0), spread(plainIn, 0) / 4.0);
}

TEST(WeightedMerge, TheWidePassPoolsAnObjectsFacesWhoseIndirectLightErrsApart) {
  // One object of reflectance 0.6 seen as two faces (a bent sheet: normals 90 degrees apart),
  // each face's estimate off by its own indirect light's error (+5 % and -5 %), 1 % noise, the
  // merge's variance wide with B's error (10 %).
  const int w = 20, h = 20;
  PixelGeometry g = wall(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      g.normal[std::size_t(y) * w + x] = glm::normalize(glm::vec3(x < w / 2 ? 1.0f : -1.0f, 0.0f, 1.0f));
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::vector<glm::vec3> r(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) r[std::size_t(y) * w + x] = glm::vec3(0.6f * (x < w / 2 ? 1.05f : 0.95f) * (1.0f + noise(rng)));
  const std::vector<float> variance(r.size(), 0.1f * 0.1f);
  const std::vector<glm::vec3> faces = smoothByNoise(r, variance, g, 32, 2.5f);
  const std::vector<glm::vec3> object = smoothByNoise(r, variance, g, 32, 2.5f, nullptr, true);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = std::size_t(y) * w + x;
      // Each face alone keeps its error; the faces together average it out.
      EXPECT_NEAR(faces[p].x, 0.6f * (x < w / 2 ? 1.05f : 0.95f), 0.003f) << x << "," << y;
      EXPECT_NEAR(object[p].x, 0.6f, 0.003f) << x << "," << y;
    }
}

TEST(WeightedMerge, AWhiteWallsNoisyEstimatesAverageToWhiteNotBelow) {
  // A white wall (reflectance 1) lit directly in three shots, 5 % noise: half of each pixel's
  // merged estimates lie above 1. Clamped before the smoothing averages them, the wall came out
  // 1.0 % dark (measured: the mean of min(1, 1 + noise)); clamped after, within its smoothed noise.
  const int w = 40, h = 40, shots = 3;
  const PixelGeometry g = wall(w, h);
  const std::size_t n = std::size_t(w) * h;
  std::mt19937 rng(13);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  std::vector<std::vector<glm::vec3>> photos(shots, std::vector<glm::vec3>(n)), direct(shots, std::vector<glm::vec3>(n)),
      indirect(shots, std::vector<glm::vec3>(n, glm::vec3(0.0f))), estimates(shots, std::vector<glm::vec3>(n));
  for (int i = 0; i < shots; ++i)
    for (std::size_t p = 0; p < n; ++p) {
      direct[i][p] = glm::vec3(0.5f * float(i + 1));
      photos[i][p] = direct[i][p] * (1.0f + noise(rng));
      estimates[i][p] = photos[i][p] / direct[i][p];
    }
  const std::vector<ConfidenceImage> lit(shots, filled(w, h, 1.0f));
  const WeightedMerge m = weightedMerge(photos, direct, indirect, estimates, lit, lit, g, WeightedMergeOptions{});
  double sum = 0.0;
  int count = 0;
  for (int y = 3; y < h - 3; ++y)
    for (int x = 3; x < w - 3; ++x) {
      const glm::vec3 r = m.reflectance[std::size_t(y) * w + x];
      EXPECT_LE(std::max({r.x, r.y, r.z}), 1.0f);
      sum += r.x;
      ++count;
    }
  EXPECT_GT(sum / count, 0.995);
}

TEST(WeightedMerge, AnObjectIsJudgedPlainTexturedOrNotAtAllByHowManyInteriorPairsItHas) {
  // Three objects on one wall: a noisy plain grey (x < 16), a 2-pixel-wide strip (16 <= x < 18)
  // that no 3 x 3 window lies wholly on, so no pair to judge it by, and a granite (x >= 18).
  const int w = 38, h = 30;
  PixelGeometry g = wall(w, h, 18);
  for (int y = 0; y < h; ++y)
    for (int x = 16; x < 18; ++x) g.object[std::size_t(y) * w + x] = 2;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> granite(0.4f, 0.8f);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  const std::size_t n = std::size_t(w) * h;
  std::vector<glm::vec3> r(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) r[std::size_t(y) * w + x] = glm::vec3(x >= 18 ? granite(rng) : 0.6f * (1.0f + noise(rng)));
  const std::vector<float> variance(n, 0.02f * 0.02f);
  const std::vector<SurfaceTexture> t = surfaceTextures(r, variance, g);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0], SurfaceTexture::Plain);
  EXPECT_EQ(t[1], SurfaceTexture::Textured);
  EXPECT_EQ(t[2], SurfaceTexture::Unjudged);
}

TEST(WeightedMerge, TilesThatNeighboursDoNotSeeAreTexturedWhereEveryShotSeesThemAndALampsErrorIsNot) {
  // Two walls, six shots. Object 0 (x < 32): tiles of 8 x 8 pixels, 0.45 or 0.55, under each
  // shot's noise of 0.03: neighbours mostly agree, tiles 4 pixels apart differ, alike in every
  // shot. Object 1 (x >= 32): one grey, each shot's estimate off by a slope of its own (a lamp's
  // error of the modelled light, 0.03 over 4 pixels, its sign from the shot), also under noise.
  const int w = 64, h = 32, shots = 6;
  const PixelGeometry g = wall(w, h, 32);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.03f);
  const std::size_t n = std::size_t(w) * h;
  std::vector<std::vector<glm::vec3>> estimates(shots, std::vector<glm::vec3>(n));
  std::vector<glm::vec3> merged(n, glm::vec3(0.0f));
  for (int i = 0; i < shots; ++i) {
    const float slope = (i % 2 == 0 ? 1.0f : -1.0f) * 0.03f / 4.0f;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t p = std::size_t(y) * w + x;
        const float truth = x < 32 ? (((x / 8) + (y / 8)) % 2 == 0 ? 0.45f : 0.55f) : 0.5f + slope * float(x - 48);
        estimates[i][p] = glm::vec3(truth + noise(rng));
        merged[p] += estimates[i][p] / float(shots);
      }
  }
  const std::vector<ConfidenceImage> lit(shots, filled(w, h, 1.0f));
  const std::vector<bool> coarse = coarselyTextured(estimates, lit, g);
  ASSERT_EQ(coarse.size(), 2u);
  EXPECT_TRUE(coarse[0]);
  EXPECT_FALSE(coarse[1]);
  // The neighbours' test alone sees the tiles only at their borders: plain.
  const std::vector<float> variance(n, 0.03f * 0.03f / float(shots) / (0.5f * 0.5f));
  EXPECT_EQ(surfaceTextures(merged, variance, g)[0], SurfaceTexture::Plain);
  // Lit in one shot alone, a pair has no second shot to repeat in: nothing to judge by.
  std::vector<ConfidenceImage> one(shots, filled(w, h, 0.0f));
  one[0] = filled(w, h, 1.0f);
  EXPECT_EQ(coarselyTextured(estimates, one, g), std::vector<bool>(2, false));
}

} // namespace
} // namespace obscura::recover
