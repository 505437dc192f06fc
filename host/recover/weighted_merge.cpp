// weighted_merge.cpp — see weighted_merge.h.
#include "recover/weighted_merge.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "core/luminance.h"
#include "core/parallel_for.h"

namespace obscura::recover {
namespace {

bool sameSurface(const PixelGeometry& g, std::size_t p, std::size_t q) {
  return g.object[q] == g.object[p] && glm::dot(g.normal[q], g.normal[p]) >= 0.95f;
}

// Calls visit(q) for every pixel q of p's clipped (2 radius + 1)^2 window on p's surface.
template <class Visit>
void forSurfaceWindow(const PixelGeometry& g, int x, int y, int radius, Visit visit) {
  const std::size_t p = std::size_t(y) * g.width + x;
  for (int wy = std::max(0, y - radius); wy <= std::min(g.height - 1, y + radius); ++wy)
    for (int wx = std::max(0, x - radius); wx <= std::min(g.width - 1, x + radius); ++wx) {
      const std::size_t q = std::size_t(wy) * g.width + wx;
      if (sameSurface(g, p, q)) visit(q);
    }
}

// Calls visit(x, y, p) for every pixel p = (x, y) that sees a surface.
template <class Visit>
void forSurfacePixels(const PixelGeometry& g, Visit visit) {
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const std::size_t p = std::size_t(y) * g.width + x;
      if (g.object[p] >= 0) visit(x, y, p);
    }
}

// Whether V_i is 0 over p's whole clipped window.
bool inShadow(const ConfidenceImage& v, int x, int y, int radius) {
  for (int wy = std::max(0, y - radius); wy <= std::min(v.height - 1, y + radius); ++wy)
    for (int wx = std::max(0, x - radius); wx <= std::min(v.width - 1, x + radius); ++wx)
      if (v.at(wx, wy) > 0.0f) return false;
  return true;
}

// Whether at least two thirds of p's clipped 3x3 window (itself included) see its surface: inside
// a surface or on its straight edge (6 of 9), not a sliver one pixel wide (a face seen edge-on),
// whose mean point and normal mix two faces and whose gathered light is then another place's.
// Of p's clipped 3x3 window (itself included): how many pixels see p's surface, and how many there are.
std::pair<int, int> surfaceSupport(const PixelGeometry& g, int x, int y) {
  int support = 0;
  forSurfaceWindow(g, x, y, 1, [&](std::size_t) { ++support; });
  const int window = (std::min(g.width - 1, x + 1) - std::max(0, x - 1) + 1) *
                     (std::min(g.height - 1, y + 1) - std::max(0, y - 1) + 1);
  return {support, window};
}

bool onSurfacePatch(const PixelGeometry& g, int x, int y) {
  const auto [support, window] = surfaceSupport(g, x, y);
  return 3 * support >= 2 * window;
}

// Whether p's whole clipped 3x3 window sees p's surface: not at an edge, where a pixel's
// footprint may mix two surfaces.
bool insideSurface(const PixelGeometry& g, int x, int y) {
  const auto [support, window] = surfaceSupport(g, x, y);
  return support == window;
}

// One more than the largest object a pixel sees: the size of a per-object table.
std::size_t objectCount(const PixelGeometry& pixels) {
  std::int32_t objects = 0;
  for (const std::int32_t o : pixels.object) objects = std::max(objects, o + 1);
  return static_cast<std::size_t>(objects);
}

double median(std::vector<double>& v) {
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

} // namespace

std::vector<float> photoNoise(const std::vector<glm::vec3>& photo, const PixelGeometry& pixels) {
  const std::size_t n = photo.size();
  // e^2 with Var(e) = sigma^2 (1 + 1/m) for m neighbours: scaled by m / (m + 1). -1: no neighbour.
  std::vector<float> residual(n, -1.0f);
  forSurfacePixels(pixels, [&](int x, int y, std::size_t p) {
    double sum = 0.0;
    int m = 0;
    forSurfaceWindow(pixels, x, y, 1, [&](std::size_t q) {
      if (q == p) return;
      sum += luminance(photo[q]);
      ++m;
    });
    if (m == 0) return;
    const double e = luminance(photo[p]) - sum / m;
    residual[p] = static_cast<float>(e * e * m / (m + 1));
  });
  std::vector<float> variance(n, 0.0f);
  forSurfacePixels(pixels, [&](int x, int y, std::size_t p) {
    double sum = 0.0;
    int m = 0;
    forSurfaceWindow(pixels, x, y, 2, [&](std::size_t q) {
      if (residual[q] < 0.0f) return;
      sum += residual[q];
      ++m;
    });
    // An isolated pixel (a sliver of its surface): a 10 % noise, a cautious guess.
    const float l = luminance(photo[p]);
    variance[p] = m > 0 ? static_cast<float>(sum / m) : 0.01f * l * l;
  });
  return variance;
}

std::vector<float> shotNoise(const std::vector<std::vector<glm::vec3>>& photos, std::size_t shot,
                             const PixelGeometry& pixels) {
  const std::vector<glm::vec3>& photo = photos.at(shot);
  std::vector<float> plain = photoNoise(photo, pixels);
  if (photos.size() < 2) return plain;
  const std::size_t n = photo.size();
  std::vector<glm::vec3> ratio(n, glm::vec3(0.0f));
  for (std::size_t p = 0; p < n; ++p) {
    float others = 0.0f;
    for (std::size_t j = 0; j < photos.size(); ++j)
      if (j != shot) others += luminance(photos[j][p]);
    if (others > 0.0f) ratio[p] = glm::vec3(luminance(photo[p]) / others);
  }
  const std::vector<float> ratioNoise = photoNoise(ratio, pixels);
  for (std::size_t p = 0; p < n; ++p) {
    // (sigma_r / r)^2 is C_i's relative variance: times C_i^2 in the photograph's units.
    const float r = ratio[p].x, c = luminance(photo[p]);
    if (r > 0.0f) plain[p] = std::min(plain[p], ratioNoise[p] / (r * r) * c * c);
  }
  return plain;
}

WeightedMerge weightedMerge(const std::vector<std::vector<glm::vec3>>& photos,
                            const std::vector<std::vector<glm::vec3>>& direct,
                            const std::vector<std::vector<glm::vec3>>& indirect,
                            const std::vector<std::vector<glm::vec3>>& estimates,
                            const std::vector<ConfidenceImage>& confidences,
                            const std::vector<ConfidenceImage>& visibility, const PixelGeometry& pixels,
                            const WeightedMergeOptions& options, const std::vector<std::vector<float>>* modelled) {
  const std::size_t shots = photos.size();
  if (direct.size() != shots || indirect.size() != shots || estimates.size() != shots || confidences.size() != shots ||
      visibility.size() != shots || (modelled && modelled->size() != shots))
    throw std::logic_error("weightedMerge: one photo, lighting, estimate and confidence per shot");
  const std::size_t n = pixels.object.size();
  WeightedMerge out;
  out.reflectance.assign(n, glm::vec3(0.0f));
  out.relativeVariance.assign(n, 0.0f);
  out.independentVariance.assign(n, 0.0f);
  out.directConfidence.assign(n, 0.0f);
  out.indirectShots.assign(n, 0.0f);
  out.weights.assign(shots, std::vector<float>(n, 0.0f));
  const float eB2 = options.indirectUncertainty * options.indirectUncertainty;
  std::vector<double> weightSum(n, 0.0), wholeSum(n, 0.0), independentSum(n, 0.0);
  std::vector<glm::dvec3> sum(n, glm::dvec3(0.0));
  std::vector<std::vector<float>> noiseOf(shots);
  parallelFor(shots, [&](std::size_t i) { noiseOf[i] = shotNoise(photos, i, pixels); });
  for (std::size_t i = 0; i < shots; ++i) {
    const std::vector<float>& noise = noiseOf[i];
    forSurfacePixels(pixels, [&](int x, int y, std::size_t p) {
      const float c = luminance(photos[i][p]), d = luminance(direct[i][p]), b = luminance(indirect[i][p]);
      if (!(c > 0.0f) || !(d + b > 0.0f)) return;
      // B's share of the light, and the share of that resting on the model's longer reach (all
      // of it without `modelled`); the floor: half-float photographs and float lighting, 0.1 %
      // at best.
      const float bShare = b / (d + b), modelShare = bShare * (modelled ? (*modelled)[i][p] : 1.0f);
      const float photoShare = noise[p] / (c * c);
      const float v = photoShare + eB2 * modelShare * modelShare + 1e-6f;
      // The merged R's variance keeps e_B on all of B (relativeVariance below): what the
      // smoothing tolerates between neighbours, whose estimates differ by B's sampling noise too,
      // most where its hidden paths are (with the weights' variance the Cornell box's faces
      // towards the open front came out blotchy: RMSE 0.0199 against 0.0171), and what weighs a
      // pixel in its object's mean (with the weights' variance a few pixels decided it: the
      // Cornell box's short box 0.769 against 0.729 at 4 spp).
      const float whole = photoShare + eB2 * bShare * bShare + 1e-6f;
      // No diffuse surface reflects more than it receives: an estimate above 1 by more than
      // three of its own standard deviations says the lighting model is wrong at this pixel,
      // not the surface. (Within them it stays: cutting a noisy estimate's upper tail alone
      // would bias what is kept low; the merged R is clamped to 1 instead, after its smoothing.)
      const glm::vec3 r = estimates[i][p];
      if (std::max({r.x, r.y, r.z}) > 1.0f + 3.0f * std::sqrt(v)) return;
      float k = confidences[i].k[p];
      if (k > 0.0f) {
        out.directConfidence[p] += k;
      } else if (b > 0.0f && inShadow(visibility[i], x, y, options.shadowRadius) && onSurfacePatch(pixels, x, y)) {
        k = 1.0f;
        out.indirectShots[p] += 1.0f;
      }
      if (k <= 0.0f) return;
      const float w = k / v;
      out.weights[i][p] = w;
      weightSum[p] += w;
      wholeSum[p] += k / whole;
      independentSum[p] += double(w) * w * photoShare;
      sum[p] += double(w) * glm::dvec3(estimates[i][p]);
    });
  }
  for (std::size_t p = 0; p < n; ++p)
    if (weightSum[p] > 0.0) {
      out.reflectance[p] = glm::vec3(sum[p] / weightSum[p]);
      out.relativeVariance[p] = static_cast<float>(1.0 / wholeSum[p]);
      out.independentVariance[p] = static_cast<float>(independentSum[p] / (weightSum[p] * weightSum[p]));
    }
  out.unsmoothed = out.reflectance;
  out.objectTextures = surfaceTextures(out.reflectance, out.independentVariance, pixels);
  const std::vector<bool> coarse = coarselyTextured(estimates, confidences, pixels);
  for (std::size_t o = 0; o < out.objectTextures.size() && o < coarse.size(); ++o)
    if (coarse[o]) out.objectTextures[o] = SurfaceTexture::Textured;
  out.reflectance = smoothMerge(out, pixels, options.smoothingRadius, options.agreement);
  return out;
}

std::vector<bool> coarselyTextured(const std::vector<std::vector<glm::vec3>>& estimates,
                                   const std::vector<ConfidenceImage>& confidences, const PixelGeometry& pixels) {
  const std::size_t count = objectCount(pixels);
  std::vector<double> consistent(count, 0.0), scatter(count, 0.0);
  std::vector<std::size_t> pairs(count, 0);
  std::vector<char> inside(pixels.object.size(), 0); // not at an edge, whose mix repeats in every shot
  forSurfacePixels(pixels, [&](int x, int y, std::size_t p) { inside[p] = insideSurface(pixels, x, y); });
  std::vector<double> d;
  forSurfacePixels(pixels, [&](int x, int y, std::size_t p) {
    if (!inside[p]) return;
    const auto pair = [&](int qx, int qy) {
      if (qx >= pixels.width || qy >= pixels.height) return;
      const std::size_t q = std::size_t(qy) * pixels.width + qx;
      if (!inside[q] || !sameSurface(pixels, p, q)) return;
      d.clear();
      for (std::size_t i = 0; i < estimates.size(); ++i)
        if (confidences[i].k[p] >= kLitConfidence && confidences[i].k[q] >= kLitConfidence)
          d.push_back(double(luminance(estimates[i][q])) - double(luminance(estimates[i][p])));
      if (d.size() < 2) return;
      double mean = 0.0, variance = 0.0;
      for (const double v : d) mean += v;
      mean /= double(d.size());
      for (const double v : d) variance += (v - mean) * (v - mean);
      variance /= double(d.size() - 1);
      const auto o = std::size_t(pixels.object[p]);
      consistent[o] += mean * mean;
      scatter[o] += variance / double(d.size());
      ++pairs[o];
    };
    pair(x + kCoarseTextureStep, y);
    pair(x, y + kCoarseTextureStep);
  });
  std::vector<bool> textured(count, false);
  for (std::size_t o = 0; o < count; ++o)
    textured[o] = pairs[o] >= kTexturePairs && scatter[o] > 0.0 && consistent[o] > kCoarseTextureRatio * scatter[o];
  return textured;
}

std::vector<glm::vec3> smoothMerge(const WeightedMerge& merged, const PixelGeometry& pixels, int radius,
                                   float agreement, bool acrossNormals) {
  std::vector<glm::vec3> out = merged.unsmoothed;
  if (radius > 0) {
    std::vector<float> tolerance = merged.relativeVariance;
    for (std::size_t p = 0; p < tolerance.size(); ++p)
      if (merged.textureOf(pixels.object[p]) == SurfaceTexture::Textured)
        tolerance[p] = merged.independentVariance[p];
    out = smoothByNoise(out, merged.relativeVariance, pixels, radius, agreement, &tolerance, acrossNormals);
  }
  // Clamped after the smoothing: a white surface's estimates scatter both sides of 1, and
  // clamping each before they average would bias it low.
  for (glm::vec3& r : out) r = glm::min(r, glm::vec3(1.0f));
  return out;
}

std::optional<glm::vec3> surfaceFill(const WeightedMerge& merged, const PixelGeometry& pixels, std::size_t p,
                                     const std::vector<bool>* whole) {
  const int x = int(p % std::size_t(pixels.width)), y = int(p / std::size_t(pixels.width));
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  int support = 0;
  forSurfaceWindow(pixels, x, y, kSurfaceFillRadius, [&](std::size_t q) {
    if (merged.relativeVariance[q] <= 0.0f || (whole && !(*whole)[q])) return;
    const double w = 1.0 / merged.relativeVariance[q];
    sum += w * glm::dvec3(merged.reflectance[q]);
    weight += w;
    ++support;
  });
  if (support < kSurfaceFillSupport) return std::nullopt;
  return glm::vec3(sum / weight);
}

std::vector<SurfaceTexture> surfaceTextures(const std::vector<glm::vec3>& reflectance,
                                            const std::vector<float>& independentVariance, const PixelGeometry& pixels) {
  const std::size_t count = objectCount(pixels);
  std::vector<std::vector<double>> differences(count), noise(count);
  std::vector<char> inside(pixels.object.size(), 0);
  forSurfacePixels(pixels, [&](int x, int y, std::size_t p) {
    inside[p] = independentVariance[p] > 0.0f && insideSurface(pixels, x, y);
  });
  forSurfacePixels(pixels, [&](int x, int y, std::size_t p) {
    if (!inside[p]) return;
    const double lp = luminance(reflectance[p]);
    const auto pair = [&](int qx, int qy) {
      if (qx >= pixels.width || qy >= pixels.height) return;
      const std::size_t q = std::size_t(qy) * pixels.width + qx;
      if (!inside[q] || !sameSurface(pixels, p, q)) return;
      const double lq = luminance(reflectance[q]);
      const auto o = std::size_t(pixels.object[p]);
      differences[o].push_back((lq - lp) * (lq - lp));
      noise[o].push_back(independentVariance[p] * lp * lp + independentVariance[q] * lq * lq);
    };
    pair(x + 1, y);
    pair(x, y + 1);
  });
  std::vector<SurfaceTexture> textures(count, SurfaceTexture::Unjudged);
  for (std::size_t o = 0; o < textures.size(); ++o) {
    if (differences[o].size() < kTexturePairs) continue;
    const double expected = median(noise[o]);
    textures[o] = expected > 0.0 && median(differences[o]) > kTextureRatio * expected ? SurfaceTexture::Textured
                                                                                      : SurfaceTexture::Plain;
  }
  return textures;
}

std::vector<glm::vec3> smoothByNoise(const std::vector<glm::vec3>& reflectance, const std::vector<float>& variance,
                                     const PixelGeometry& pixels, int radius, float agreement,
                                     const std::vector<float>* tolerance, bool acrossNormals) {
  std::vector<glm::vec3> out = reflectance;
  const float a2 = agreement * agreement;
  const std::vector<float>& within = tolerance ? *tolerance : variance;
  parallelFor(std::size_t(pixels.height), [&](std::size_t row) {
    const int y = int(row);
    for (int x = 0; x < pixels.width; ++x) {
      const std::size_t p = std::size_t(y) * pixels.width + x;
      if (pixels.object[p] < 0 || variance[p] <= 0.0f) continue;
      const glm::vec3 rp = reflectance[p];
      const glm::vec3 sp = within[p] * rp * rp; // per channel sigma^2
      glm::dvec3 sum(0.0);
      double weight = 0.0;
      for (int wy = std::max(0, y - radius); wy <= std::min(pixels.height - 1, y + radius); ++wy)
        for (int wx = std::max(0, x - radius); wx <= std::min(pixels.width - 1, x + radius); ++wx) {
          const std::size_t q = std::size_t(wy) * pixels.width + wx;
          const bool alike = acrossNormals ? pixels.object[q] == pixels.object[p] : sameSurface(pixels, p, q);
          if (!alike || variance[q] <= 0.0f) continue;
          const glm::vec3 rq = reflectance[q];
          const glm::vec3 d = rq - rp, s = sp + within[q] * rq * rq;
          if (d.x * d.x > a2 * s.x || d.y * d.y > a2 * s.y || d.z * d.z > a2 * s.z) continue;
          // Relative variances weigh: absolute ones would favour the darker of two noisy pixels.
          const double w = 1.0 / variance[q];
          sum += w * glm::dvec3(rq);
          weight += w;
        }
      out[p] = glm::vec3(sum / weight);
    }
  });
  return out;
}

} // namespace obscura::recover
