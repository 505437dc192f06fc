// texture_fill.cpp — see texture_fill.h.
#include "recover/texture_fill.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <glm/gtc/constants.hpp>

namespace obscura::recover {
namespace {

constexpr int kTile = 16;             // tile side, pixels
constexpr int kStep = kTile / 2;     // tiles overlap by half: the raised-cosine weights sum to 1
constexpr int kRim = 4;              // pixels: how far a source pixel must be from the source's edge to give the mean and tiles
constexpr int kMeanRadius = 12;      // the local mean: a 25x25 window
constexpr float kSamePlane = 0.95f;  // normals of one surface

struct Surface {
  std::int32_t object = -1;
  glm::vec3 normal{0.0f};
  std::vector<std::size_t> hole;
};

// A summed-area table of `values` (width + 1) x (height + 1), for box sums.
template <typename T>
std::vector<T> summedArea(const std::vector<T>& values, int width, int height) {
  std::vector<T> table(std::size_t(width + 1) * (height + 1), T(0));
  for (int y = 0; y < height; ++y) {
    T row(0);
    for (int x = 0; x < width; ++x) {
      row += values[std::size_t(y) * width + x];
      table[std::size_t(y + 1) * (width + 1) + x + 1] = table[std::size_t(y) * (width + 1) + x + 1] + row;
    }
  }
  return table;
}

// The sum over [x0, x1) x [y0, y1), clamped to the image.
template <typename T>
T boxSum(const std::vector<T>& table, int width, int height, int x0, int y0, int x1, int y1) {
  x0 = std::clamp(x0, 0, width);
  x1 = std::clamp(x1, 0, width);
  y0 = std::clamp(y0, 0, height);
  y1 = std::clamp(y1, 0, height);
  const auto at = [&](int x, int y) { return table[std::size_t(y) * (width + 1) + x]; };
  return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
}

// The raised-cosine weight of position i (0 .. kTile - 1) in a tile: w(i) + w(i + kStep) = 1.
float tileWeight(int i) {
  const float s = std::sin(glm::pi<float>() * (float(i) + 0.5f) / float(kTile));
  return s * s;
}

} // namespace

std::vector<glm::vec3> fillByTexture(const TextureFillInput& in, TextureFillReport* report) {
  const int W = in.width, H = in.height;
  const std::size_t pixels = std::size_t(W) * H;
  std::vector<glm::vec3> out = in.reflectance;
  TextureFillReport local;
  // The hole's surfaces: one per object and plane.
  std::vector<Surface> surfaces;
  for (std::size_t p = 0; p < pixels; ++p) {
    if (!in.hole[p] || in.object[p] < 0) continue;
    ++local.holePixels;
    auto it = std::find_if(surfaces.begin(), surfaces.end(), [&](const Surface& s) {
      return s.object == in.object[p] && glm::dot(s.normal, in.normal[p]) > kSamePlane;
    });
    if (it == surfaces.end()) it = surfaces.insert(surfaces.end(), Surface{in.object[p], in.normal[p], {}});
    it->hole.push_back(p);
  }
  std::mt19937 random(in.seed);
  for (const Surface& surface : surfaces) {
    auto onSurface = [&](std::size_t p) {
      return in.object[p] == surface.object && glm::dot(in.normal[p], surface.normal) > kSamePlane;
    };
    std::vector<float> sourceMask(pixels, 0.0f);
    std::vector<glm::dvec3> sourceValue(pixels, glm::dvec3(0.0));
    std::size_t sources = 0;
    for (std::size_t p = 0; p < pixels; ++p)
      if (in.source[p] && !in.hole[p] && onSurface(p)) {
        sourceMask[p] = 1.0f;
        sourceValue[p] = glm::dvec3(in.reflectance[p]);
        ++sources;
      }
    if (sources == 0) continue; // nothing of this surface was photographed: left as it was
    const auto maskTable = summedArea(sourceMask, W, H);
    const auto valueTable = summedArea(sourceValue, W, H);
    // Whether a source pixel is kRim pixels clear of the source's edge (its window inside the
    // image wholly source): the rim holds the recovery's edge errors (footprints that mix
    // surfaces), several times the interior's variance, which a fill should copy neither into its
    // mean nor into its texture.
    const auto clear = [&](int x, int y, int w, int h) {
      const int rx0 = std::max(0, x - kRim), ry0 = std::max(0, y - kRim);
      const int rx1 = std::min(W, x + w + kRim), ry1 = std::min(H, y + h + kRim);
      return boxSum(maskTable, W, H, rx0, ry0, rx1, ry1) == float((rx1 - rx0) * (ry1 - ry0));
    };
    std::vector<float> clearMask(pixels, 0.0f);
    std::vector<glm::dvec3> clearValue(pixels, glm::dvec3(0.0));
    std::size_t clearSources = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t p = std::size_t(y) * W + x;
        if (sourceMask[p] == 0.0f || !clear(x, y, 1, 1)) continue;
        clearMask[p] = 1.0f;
        clearValue[p] = sourceValue[p];
        ++clearSources;
      }
    // A surface photographed only along its rim (a sliver of mixed normals at an edge) has
    // nothing but edge errors to copy: left as it was (the caller's guess, remodel's object mean).
    if (clearSources == 0) {
      local.rimOnly += surface.hole.size();
      continue;
    }
    const auto clearMaskTable = summedArea(clearMask, W, H);
    const auto clearValueTable = summedArea(clearValue, W, H);
    glm::dvec3 globalMean = boxSum(valueTable, W, H, 0, 0, W, H) / double(sources);
    // M over the source: the 25x25 mean of the surface's source pixels clear of its rim (of all
    // its source pixels where the window holds none).
    std::vector<glm::vec3> mean(pixels, glm::vec3(globalMean));
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t p = std::size_t(y) * W + x;
        if (sourceMask[p] == 0.0f) continue;
        const int x0 = x - kMeanRadius, y0 = y - kMeanRadius, x1 = x + kMeanRadius + 1, y1 = y + kMeanRadius + 1;
        const float inside = boxSum(clearMaskTable, W, H, x0, y0, x1, y1);
        mean[p] = inside > 0.0f
                      ? glm::vec3(boxSum(clearValueTable, W, H, x0, y0, x1, y1) / double(inside))
                      : glm::vec3(boxSum(valueTable, W, H, x0, y0, x1, y1) / double(boxSum(maskTable, W, H, x0, y0, x1, y1)));
      }
    // M inside the hole: Laplace's equation with the source's M on the border (Dirichlet) and
    // nothing across other surfaces (Neumann), by successive over-relaxation.
    std::vector<std::uint8_t> inHole(pixels, 0);
    for (std::size_t p : surface.hole) inHole[p] = 1;
    const int sweeps = 4 * (W + H);
    for (int sweep = 0; sweep < sweeps; ++sweep) {
      float change = 0.0f;
      for (std::size_t p : surface.hole) {
        const int x = int(p % std::size_t(W)), y = int(p / std::size_t(W));
        glm::vec3 sum(0.0f);
        int n = 0;
        const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
        for (int k = 0; k < 4; ++k) {
          const int nx = x + dx[k], ny = y + dy[k];
          if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
          const std::size_t q = std::size_t(ny) * W + nx;
          if (!inHole[q] && sourceMask[q] == 0.0f) continue;
          sum += mean[q];
          ++n;
        }
        if (n == 0) continue;
        const glm::vec3 next = mean[p] + 1.8f * (sum / float(n) - mean[p]);
        change = std::max(change, glm::length(next - mean[p]));
        mean[p] = next;
      }
      if (change < 1e-6f) break;
    }
    // D: tiles of the source's deviation from its mean, from windows the photographs saw fully,
    // clear of the rim where the surface has such windows.
    std::vector<std::pair<int, int>> tiles;
    for (const bool clearOfRim : {true, false}) {
      for (int y = 0; y + kTile <= H; ++y)
        for (int x = 0; x + kTile <= W; ++x)
          if (clearOfRim ? clear(x, y, kTile, kTile)
                         : boxSum(maskTable, W, H, x, y, x + kTile, y + kTile) == float(kTile * kTile))
            tiles.emplace_back(x, y);
      if (!tiles.empty()) break;
    }
    if (tiles.empty()) {
      for (std::size_t p : surface.hole) out[p] = glm::max(mean[p], glm::vec3(0.0f));
      local.meanOnly += surface.hole.size();
      continue;
    }
    int x0 = W, y0 = H, x1 = 0, y1 = 0;
    for (std::size_t p : surface.hole) {
      x0 = std::min(x0, int(p % std::size_t(W)));
      x1 = std::max(x1, int(p % std::size_t(W)));
      y0 = std::min(y0, int(p / std::size_t(W)));
      y1 = std::max(y1, int(p / std::size_t(W)));
    }
    std::vector<glm::vec3> weighted(pixels, glm::vec3(0.0f));
    std::vector<float> weightSquares(pixels, 0.0f);
    for (int ty = y0 - kStep; ty <= y1; ty += kStep)
      for (int tx = x0 - kStep; tx <= x1; tx += kStep) {
        const auto& [sx, sy] = tiles[random() % tiles.size()];
        bool used = false;
        for (int j = 0; j < kTile; ++j)
          for (int i = 0; i < kTile; ++i) {
            const int x = tx + i, y = ty + j;
            if (x < 0 || y < 0 || x >= W || y >= H) continue;
            const std::size_t p = std::size_t(y) * W + x;
            if (!inHole[p]) continue;
            const std::size_t q = std::size_t(sy + j) * W + std::size_t(sx + i);
            const float w = tileWeight(i) * tileWeight(j);
            weighted[p] += w * (in.reflectance[q] - mean[q]);
            weightSquares[p] += w * w;
            used = true;
          }
        if (used) ++local.tiles;
      }
    for (std::size_t p : surface.hole)
      out[p] = glm::max(mean[p] + weighted[p] / std::sqrt(std::max(weightSquares[p], 1e-12f)), glm::vec3(0.0f));
  }
  if (report) *report = local;
  return out;
}

} // namespace obscura::recover
