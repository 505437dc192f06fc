// texture_fill_test.cpp — the fill of never-photographed pixels from their surface, on a small
// synthetic view with a known answer: what the source's rim may and may not give.
#include "recover/texture_fill.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

namespace obscura::recover {
namespace {

TEST(TextureFill, AHoleTakesItsSurfacesInteriorNotTheEdgeErrorsOfTheRimAroundIt) {
  // An 80 x 80 wall (object 0) of reflectance 0.5 with a 12 x 12 hole in its middle (a removed
  // object's silhouette). The two pixels of wall around the hole carry the recovery's edge errors
  // (0.3). A second surface of the same object (another normal: a sliver along the hole's top
  // edge) is photographed only within that rim.
  const int w = 80, h = 80;
  const std::size_t n = std::size_t(w) * h;
  TextureFillInput in;
  in.width = w;
  in.height = h;
  in.reflectance.assign(n, glm::vec3(0.5f));
  in.object.assign(n, 0);
  in.normal.assign(n, glm::vec3(0.0f, 0.0f, 1.0f));
  in.source.assign(n, 1);
  in.hole.assign(n, 0);
  const auto at = [&](int x, int y) { return std::size_t(y) * w + x; };
  const auto inHole = [](int x, int y) { return x >= 34 && x < 46 && y >= 34 && y < 46; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (inHole(x, y)) {
        in.hole[at(x, y)] = 1;
        in.source[at(x, y)] = 0;
        in.reflectance[at(x, y)] = glm::vec3(0.0f);
      } else if (x >= 32 && x < 48 && y >= 32 && y < 48) {
        in.reflectance[at(x, y)] = glm::vec3(0.3f); // the rim
      }
    }
  const glm::vec3 sliverGuess(0.9f);
  for (int x = 34; x < 46; ++x) {
    in.normal[at(x, 33)] = in.normal[at(x, 34)] = glm::vec3(0.0f, 1.0f, 0.0f);
    in.reflectance[at(x, 34)] = sliverGuess; // the caller's guess for it (remodel: the object's mean)
  }
  TextureFillReport report;
  const std::vector<glm::vec3> out = fillByTexture(in, &report);
  double sum = 0.0, worst = 0.0;
  int count = 0;
  for (int y = 35; y < 46; ++y)
    for (int x = 34; x < 46; ++x) {
      const double r = out[at(x, y)].x;
      sum += r;
      worst = std::max(worst, std::abs(r - 0.5));
      ++count;
    }
  // The wall's interior is flat 0.5: the fill's mean from the rim-free 25 x 25 windows is 0.5 and
  // its texture (the interior's deviations) nothing; with the rim in them the border rows came out
  // ~0.4 and the rim's step was copied as texture.
  EXPECT_NEAR(sum / count, 0.5, 1e-3);
  EXPECT_LT(worst, 0.01);
  // The sliver's only photographed pixels are rim pixels: it keeps the caller's guess.
  EXPECT_EQ(report.rimOnly, 12u);
  for (int x = 34; x < 46; ++x) EXPECT_EQ(out[at(x, 34)], sliverGuess) << x;
}

} // namespace
} // namespace obscura::recover
