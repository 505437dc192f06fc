// confidence_filters.h — the confidence images of reflectance recovery and their filters
// [IVR §4.3], and the merge of the per-photo estimates [IVR eq. 3].
//
// A confidence image K_i starts as the visibility V_i of the photo's lamp (K_i = V_i, IVR §4.1).
// The filters, in the paper's order:
//   1. 5x5 min                        widens shadows: V near a shadow edge depends on the exact
//                                     geometry and lamp size, so it is not trusted
//   2. 5x5 smoothing, lowering only   K := min(K, mean of 5x5): smooth transitions between photos
//   3. outlier test across photos     per pixel, mu = median of the R_i with K_i > eps1; any photo
//                                     with |R_i - mu| > eps2 (largest channel) gets K_i = 0
//   4. 3x3 smoothing                  K := mean of 3x3, so the merge blends photos smoothly;
//                                     OURS: pixels step 3 rejected stay 0 (see the .cpp)
// Windows are clipped at the image border (the mean is over the pixels inside).
// OURS: given the pixels' surfaces (Surfaces below), every window holds only the pixels of its
// centre's surface. The filters distrust V at shadow edges; a pixel beside another surface is at
// no shadow edge of its own. In image windows a chair's frame, a few pixels wide against a floor
// in its shadow, lost its confidence to the floor (classroom: 6,800 pixels were filled instead of
// merged), and a face seen edge-on took confidence from its lit neighbours.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace obscura::recover {

struct ConfidenceImage {
  int width = 0, height = 0;
  std::vector<float> k; // rows top to bottom
  float at(int x, int y) const { return k[std::size_t(y) * width + x]; }
};

struct FilterOptions {
  bool minFilter = true;       // step 1
  bool lowerSmoothing = true;  // step 2
  bool outlier = true;         // step 3
  bool finalSmoothing = true;  // step 4
  float outlierConfidence = 0.75f; // eps1
  float outlierDistance = 0.3f;    // eps2
};

// Which pixels show the same surface: the same object, normals within ~18 degrees (what the
// camera saw per pixel). A window filter given one reads only the pixels of the centre's surface.
struct Surfaces {
  const std::vector<std::int32_t>* object = nullptr;
  const std::vector<glm::vec3>* normal = nullptr;
  bool same(std::size_t p, std::size_t q) const {
    return p == q || ((*object)[p] == (*object)[q] && glm::dot((*normal)[p], (*normal)[q]) >= 0.95f);
  }
};

// Step 1: each K replaced by the minimum over the (2 radius + 1)^2 window (of its surface's
// pixels, with `surfaces`).
ConfidenceImage minFilter(const ConfidenceImage& in, int radius, const Surfaces* surfaces = nullptr);
// Step 2: K := min(K, window mean) over the (2 radius + 1)^2 window.
ConfidenceImage lowerSmoothing(const ConfidenceImage& in, int radius, const Surfaces* surfaces = nullptr);
// Step 4: K := window mean over the (2 radius + 1)^2 window.
ConfidenceImage smoothing(const ConfidenceImage& in, int radius, const Surfaces* surfaces = nullptr);
// Step 3 on every photo's confidence at once (estimates[i][pixel], confidences[i]).
void outlierTest(const std::vector<std::vector<glm::vec3>>& estimates, std::vector<ConfidenceImage>& confidences,
                 float minConfidence, float maxDistance);
// Steps 1-4 as `options` enables them, on copies of the visibilities.
std::vector<ConfidenceImage> filterConfidences(const std::vector<std::vector<glm::vec3>>& estimates,
                                               const std::vector<ConfidenceImage>& visibilities,
                                               const FilterOptions& options, const Surfaces* surfaces = nullptr);

struct Merged {
  std::vector<glm::vec3> reflectance; // sum K_i R_i / sum K_i; (0, 0, 0) where sum K_i = 0
  std::vector<float> confidence;      // sum K_i
};
// IVR eq. 3.
Merged mergeEstimates(const std::vector<std::vector<glm::vec3>>& estimates,
                      const std::vector<ConfidenceImage>& confidences);

} // namespace obscura::recover
