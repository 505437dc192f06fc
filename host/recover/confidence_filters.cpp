// confidence_filters.cpp — see confidence_filters.h.
#include "recover/confidence_filters.h"

#include <algorithm>
#include <stdexcept>

#include "core/parallel_for.h"

namespace obscura::recover {
namespace {

// Applies `reduce(first, last, centre)` to each clipped window's values.
template <class Reduce>
ConfidenceImage windowFilter(const ConfidenceImage& in, int radius, Reduce reduce, const Surfaces* surfaces = nullptr) {
  ConfidenceImage out = in;
  std::vector<float> window;
  window.reserve(std::size_t(2 * radius + 1) * (2 * radius + 1));
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      window.clear();
      for (int wy = std::max(0, y - radius); wy <= std::min(in.height - 1, y + radius); ++wy)
        for (int wx = std::max(0, x - radius); wx <= std::min(in.width - 1, x + radius); ++wx)
          if (!surfaces || surfaces->same(std::size_t(y) * in.width + x, std::size_t(wy) * in.width + wx))
            window.push_back(in.at(wx, wy));
      out.k[std::size_t(y) * in.width + x] = reduce(window, in.at(x, y));
    }
  return out;
}

float mean(const std::vector<float>& values) {
  double sum = 0.0;
  for (float v : values) sum += v;
  return static_cast<float>(sum / static_cast<double>(values.size()));
}

// The median of a non-empty list (the mean of the middle two for an even count).
float median(std::vector<float> values) {
  const std::size_t n = values.size(), mid = n / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  const float upper = values[mid];
  if (n % 2 == 1) return upper;
  return 0.5f * (upper + *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid)));
}

} // namespace

ConfidenceImage minFilter(const ConfidenceImage& in, int radius, const Surfaces* surfaces) {
  return windowFilter(
      in, radius, [](const std::vector<float>& w, float) { return *std::min_element(w.begin(), w.end()); }, surfaces);
}

ConfidenceImage lowerSmoothing(const ConfidenceImage& in, int radius, const Surfaces* surfaces) {
  return windowFilter(
      in, radius, [](const std::vector<float>& w, float centre) { return std::min(centre, mean(w)); }, surfaces);
}

ConfidenceImage smoothing(const ConfidenceImage& in, int radius, const Surfaces* surfaces) {
  return windowFilter(in, radius, [](const std::vector<float>& w, float) { return mean(w); }, surfaces);
}

void outlierTest(const std::vector<std::vector<glm::vec3>>& estimates, std::vector<ConfidenceImage>& confidences,
                 float minConfidence, float maxDistance) {
  if (estimates.size() != confidences.size()) throw std::logic_error("outlierTest: one confidence per estimate");
  if (confidences.empty()) return;
  const std::size_t pixels = confidences.front().k.size();
  std::vector<float> table[3];
  for (std::size_t p = 0; p < pixels; ++p) {
    for (auto& t : table) t.clear();
    for (std::size_t i = 0; i < estimates.size(); ++i)
      if (confidences[i].k[p] > minConfidence)
        for (int c = 0; c < 3; ++c) table[c].push_back(estimates[i][p][c]);
    if (table[0].empty()) continue;
    const glm::vec3 mu(median(table[0]), median(table[1]), median(table[2]));
    for (std::size_t i = 0; i < estimates.size(); ++i) {
      const glm::vec3 d = glm::abs(estimates[i][p] - mu);
      if (std::max({d.x, d.y, d.z}) > maxDistance) confidences[i].k[p] = 0.0f;
    }
  }
}

std::vector<ConfidenceImage> filterConfidences(const std::vector<std::vector<glm::vec3>>& estimates,
                                               const std::vector<ConfidenceImage>& visibilities,
                                               const FilterOptions& options, const Surfaces* surfaces) {
  std::vector<ConfidenceImage> k = visibilities;
  parallelFor(k.size(), [&](std::size_t i) { // each photo's on its own
    if (options.minFilter) k[i] = minFilter(k[i], 2, surfaces);
    if (options.lowerSmoothing) k[i] = lowerSmoothing(k[i], 2, surfaces);
  });
  std::vector<ConfidenceImage> beforeOutlier = k;
  if (options.outlier) outlierTest(estimates, k, options.outlierConfidence, options.outlierDistance);
  if (options.finalSmoothing)
    parallelFor(k.size(), [&](std::size_t i) {
      const ConfidenceImage afterOutlier = k[i];
      k[i] = smoothing(k[i], 1, surfaces);
      // OURS: a rejected estimate stays rejected. The paper's smoothing gives the rim of a
      // rejected region (a lamp fixture) a third of a photo's weight back, and an outlier 10
      // times the reflectance shows through at that weight.
      for (std::size_t p = 0; p < k[i].k.size(); ++p)
        if (beforeOutlier[i].k[p] > 0.0f && afterOutlier.k[p] == 0.0f) k[i].k[p] = 0.0f;
    });
  return k;
}

Merged mergeEstimates(const std::vector<std::vector<glm::vec3>>& estimates,
                      const std::vector<ConfidenceImage>& confidences) {
  Merged m;
  const std::size_t pixels = confidences.empty() ? 0 : confidences.front().k.size();
  m.reflectance.assign(pixels, glm::vec3(0.0f));
  m.confidence.assign(pixels, 0.0f);
  for (std::size_t p = 0; p < pixels; ++p) {
    glm::vec3 sum(0.0f);
    float weight = 0.0f;
    for (std::size_t i = 0; i < estimates.size(); ++i) {
      sum += confidences[i].k[p] * estimates[i][p];
      weight += confidences[i].k[p];
    }
    m.confidence[p] = weight;
    if (weight > 0.0f) m.reflectance[p] = sum / weight;
  }
  return m;
}

} // namespace obscura::recover
