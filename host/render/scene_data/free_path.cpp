#include "render/scene_data/free_path.h"

#include "render/scene_data/camera_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace obscura::render {

float boundsDMax(const scene::Bounds& bounds) {
  glm::vec3 e = bounds.extent();
  float largest = std::max(e.x, std::max(e.y, e.z));
  return largest > 0.0f && std::isfinite(largest) ? 0.25f * largest : 1.0f;
}

FreePath measureFreePath(const scene::Scene& scene, const bvh::Bvh& bvh, const scene::Camera& camera) {
  constexpr int kGrid = 48;
  FreePath out;
  const float aspect = camera.aspectRatio > 0.0f ? camera.aspectRatio : 4.0f / 3.0f;
  const GridCamera view{camera.position, camera.forward, camera.up, camera.yfov, aspect};
  const float extent = 4.0f * boundsDMax(scene.bounds); // the largest side
  std::mt19937 rng(0xd15ca1u);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<float> distances;
  std::size_t escaped = 0;
  for (int y = 0; y < kGrid; ++y)
    for (int x = 0; x < kGrid; ++x) {
      const auto seen = firstHitThroughGrid(scene, bvh, view, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, kGrid);
      if (!seen) continue;
      const glm::vec3 p = seen->position, n = seen->normal;
      float offset = std::max(1e-5f * extent, 4e-6f * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}));
      // Cosine direction about n.
      glm::vec3 helper = std::abs(n.x) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
      glm::vec3 tx = glm::normalize(glm::cross(helper, n)), ty = glm::cross(n, tx);
      float u1 = uni(rng), u2 = uni(rng), r = std::sqrt(u1), phi = 2.0f * std::numbers::pi_v<float> * u2;
      glm::vec3 w = r * std::cos(phi) * tx + r * std::sin(phi) * ty + std::sqrt(std::max(0.0f, 1.0f - u1)) * n;
      bvh::Hit next = bvh::closestHit(bvh, {.origin = p + offset * n, .direction = w});
      ++out.rays;
      if (next.hit()) distances.push_back(next.t);
      else ++escaped;
    }
  if (out.rays == 0) return out;
  out.escaped = static_cast<double>(escaped) / out.rays;
  // Escaped rays are longer than any hit: the median is among the hits only while fewer than half left.
  const std::size_t middle = out.rays / 2;
  if (middle < distances.size()) {
    std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(middle), distances.end());
    out.median = distances[middle];
  } else {
    out.median = std::numeric_limits<float>::infinity();
  }
  return out;
}

float defaultDMax(const scene::Scene& scene, const bvh::Bvh& bvh, const scene::Camera& camera) {
  return defaultDMax(scene, measureFreePath(scene, bvh, camera));
}

float defaultDMax(const scene::Scene& scene, const FreePath& f) {
  if (f.rays == 0 || !std::isfinite(f.median) || !(f.median > 0.0f)) return boundsDMax(scene.bounds);
  return 0.5f * f.median;
}

} // namespace obscura::render
