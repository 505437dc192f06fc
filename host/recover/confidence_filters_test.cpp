// confidence_filters_test.cpp — the paper's confidence filters [IVR §4.3] on small images with
// answers worked out by hand.
#include "recover/confidence_filters.h"

#include <gtest/gtest.h>

namespace obscura::recover {
namespace {

ConfidenceImage filled(int w, int h, float v) { return {w, h, std::vector<float>(std::size_t(w) * h, v)}; }

TEST(ConfidenceFilters, MinFilterWidensAShadowPixelToItsFiveByFiveWindow) {
  ConfidenceImage k = filled(9, 9, 1.0f);
  k.k[4 * 9 + 4] = 0.0f;
  const ConfidenceImage out = minFilter(k, 2);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x)
      EXPECT_EQ(out.at(x, y), (std::abs(x - 4) <= 2 && std::abs(y - 4) <= 2) ? 0.0f : 1.0f) << x << "," << y;
}

TEST(ConfidenceFilters, LowerSmoothingOnlyLowersAndTakesTheClippedWindowMean) {
  ConfidenceImage k = filled(6, 6, 1.0f);
  for (int y = 0; y < 6; ++y) k.k[std::size_t(y) * 6 + 0] = 0.0f; // a dark first column
  const ConfidenceImage out = lowerSmoothing(k, 2);
  for (std::size_t p = 0; p < k.k.size(); ++p) EXPECT_LE(out.k[p], k.k[p]);
  // Pixel (1, 2): its window is x 0..3, y 0..4 (clipped): 20 pixels, 5 of them 0.
  EXPECT_FLOAT_EQ(out.at(1, 2), 15.0f / 20.0f);
  // The dark column stays 0 (the window mean is higher, so it is not raised).
  EXPECT_EQ(out.at(0, 3), 0.0f);
  // Pixel (3, 3): x 1..5, y 1..5, no dark pixel.
  EXPECT_EQ(out.at(3, 3), 1.0f);
}

TEST(ConfidenceFilters, SmoothingIsTheThreeByThreeMean) {
  ConfidenceImage k = filled(3, 3, 0.0f);
  k.k[4] = 9.0f;
  const ConfidenceImage out = smoothing(k, 1);
  EXPECT_FLOAT_EQ(out.at(1, 1), 1.0f);
  EXPECT_FLOAT_EQ(out.at(0, 0), 9.0f / 4.0f); // corner window: 4 pixels
}

// A 9 x 9 view of a floor (object 0, facing up) with a strip across it at column 4: a chair's
// frame (object 1), or, with `crease`, a face of the floor's own object turned 90 degrees.
struct StripView {
  std::vector<std::int32_t> object;
  std::vector<glm::vec3> normal;
  Surfaces surfaces() const { return {&object, &normal}; }
};
StripView stripView(bool crease) {
  StripView v;
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) {
      const bool strip = x == 4;
      v.object.push_back(strip && !crease ? 1 : 0);
      v.normal.push_back(strip && crease ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0));
    }
  return v;
}

TEST(ConfidenceFilters, FiltersAlongSurfacesKeepAThinLitStripBesideAShadowedSurface) {
  for (const bool crease : {false, true}) {
    const StripView view = stripView(crease);
    const Surfaces surfaces = view.surfaces();
    ConfidenceImage k = filled(9, 9, 0.0f); // the floor in the lamp's shadow, the strip lit
    for (int y = 0; y < 9; ++y) k.k[std::size_t(y) * 9 + 4] = 1.0f;
    // In image windows the floor's shadow takes the strip's confidence; along surfaces it stays.
    EXPECT_EQ(minFilter(k, 2).at(4, 4), 0.0f);
    EXPECT_FLOAT_EQ(lowerSmoothing(k, 2).at(4, 4), 0.2f);
    EXPECT_FLOAT_EQ(smoothing(k, 1).at(3, 4), 1.0f / 3.0f); // and gives the floor a third
    for (int y = 0; y < 9; ++y) {
      EXPECT_EQ(minFilter(k, 2, &surfaces).at(4, y), 1.0f) << "crease " << crease << ", row " << y;
      EXPECT_EQ(lowerSmoothing(k, 2, &surfaces).at(4, y), 1.0f);
      EXPECT_EQ(smoothing(k, 1, &surfaces).at(3, y), 0.0f);
    }
    // A shadow edge on the strip itself is still widened: its own pixels' window.
    k.k[4 * 9 + 4] = 0.0f;
    const ConfidenceImage widened = minFilter(k, 2, &surfaces);
    for (int y = 0; y < 9; ++y) EXPECT_EQ(widened.at(4, y), std::abs(y - 4) <= 2 ? 0.0f : 1.0f) << y;
  }
}

TEST(ConfidenceFilters, APixelWithoutANormalIsItsOwnSurface) {
  // A face seen edge-on: its pixels' mean normal is no unit vector. Its window is itself.
  StripView view = stripView(false);
  view.normal[4 * 9 + 4] = glm::vec3(0.0f);
  const Surfaces surfaces = view.surfaces();
  ConfidenceImage k = filled(9, 9, 1.0f);
  k.k[4 * 9 + 4] = 0.0f;
  EXPECT_EQ(smoothing(k, 1, &surfaces).at(4, 4), 0.0f);
  EXPECT_EQ(minFilter(k, 2, &surfaces).at(4, 3), 1.0f);
}

TEST(ConfidenceFilters, OutlierTestRejectsEstimatesFarFromTheMedianOfConfidentPhotos) {
  // One pixel, four photos: three confident ones at 0.5, 0.52, 0.9 (median 0.52), one not
  // confident (K = 0.5 <= eps1) at 0.1, which does not vote but is tested.
  std::vector<std::vector<glm::vec3>> r = {{glm::vec3(0.5f)}, {glm::vec3(0.52f)}, {glm::vec3(0.5f, 0.5f, 0.9f)},
                                           {glm::vec3(0.1f)}};
  std::vector<ConfidenceImage> k = {filled(1, 1, 1.0f), filled(1, 1, 0.9f), filled(1, 1, 1.0f), filled(1, 1, 0.5f)};
  outlierTest(r, k, 0.75f, 0.3f);
  EXPECT_EQ(k[0].k[0], 1.0f);
  EXPECT_EQ(k[1].k[0], 0.9f);
  EXPECT_EQ(k[2].k[0], 0.0f); // blue 0.9 is 0.38 from 0.52
  EXPECT_EQ(k[3].k[0], 0.0f); // 0.42 from 0.5
  // With no confident photo nothing is rejected.
  std::vector<ConfidenceImage> low = {filled(1, 1, 0.2f), filled(1, 1, 0.2f), filled(1, 1, 0.2f), filled(1, 1, 0.2f)};
  outlierTest(r, low, 0.75f, 0.3f);
  for (const auto& image : low) EXPECT_EQ(image.k[0], 0.2f);
}

TEST(ConfidenceFilters, MergeIsTheConfidenceWeightedMean) {
  std::vector<std::vector<glm::vec3>> r = {{glm::vec3(0.2f), glm::vec3(1.0f)}, {glm::vec3(0.8f), glm::vec3(3.0f)}};
  std::vector<ConfidenceImage> k = {{2, 1, {1.0f, 0.0f}}, {2, 1, {0.5f, 0.0f}}};
  const Merged m = mergeEstimates(r, k);
  EXPECT_FLOAT_EQ(m.reflectance[0].x, (0.2f + 0.5f * 0.8f) / 1.5f);
  EXPECT_FLOAT_EQ(m.confidence[0], 1.5f);
  EXPECT_EQ(m.reflectance[1], glm::vec3(0.0f)); // no confidence: left for the fill
  EXPECT_EQ(m.confidence[1], 0.0f);
}

TEST(ConfidenceFilters, FinalSmoothingDoesNotGiveRejectedEstimatesWeightBack) {
  // Three photos of a 5x5 image agree at 0.5 but for photo 0's 3x3 centre (a fixture at 5.0):
  // the outlier test rejects it, and the 3x3 smoothing must not bring it back at the rim.
  std::vector<std::vector<glm::vec3>> r(3, std::vector<glm::vec3>(25, glm::vec3(0.5f)));
  for (int y = 1; y <= 3; ++y)
    for (int x = 1; x <= 3; ++x) r[0][std::size_t(y) * 5 + x] = glm::vec3(5.0f);
  FilterOptions o;
  o.minFilter = o.lowerSmoothing = false;
  const auto k = filterConfidences(r, {filled(5, 5, 1.0f), filled(5, 5, 1.0f), filled(5, 5, 1.0f)}, o);
  for (int y = 1; y <= 3; ++y)
    for (int x = 1; x <= 3; ++x) EXPECT_EQ(k[0].at(x, y), 0.0f) << x << "," << y;
  EXPECT_FLOAT_EQ(k[0].at(0, 0), 3.0f / 4.0f); // outside: smoothed with the rejected neighbour
  EXPECT_FLOAT_EQ(k[1].at(2, 2), 1.0f);
  const Merged m = mergeEstimates(r, k);
  for (std::size_t p = 0; p < 25; ++p) EXPECT_NEAR(m.reflectance[p].x, 0.5f, 1e-6f) << p;
}

} // namespace
} // namespace obscura::recover
