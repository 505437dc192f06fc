#include "render/scene_data/camera_grid.h"

#include <cmath>

namespace obscura::render {

std::optional<GridHit> firstHitThroughGrid(const scene::Scene& scene, const bvh::Bvh& bvh, const GridCamera& camera,
                                           float gx, float gy, int grid) {
  const float tanHalf = std::tan(0.5f * camera.yfov);
  const glm::vec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
  const float g = static_cast<float>(grid);
  const float sx = (2.0f * gx / g - 1.0f) * tanHalf * camera.aspect;
  const float sy = (1.0f - 2.0f * gy / g) * tanHalf;
  const glm::vec3 d = glm::normalize(camera.forward + sx * right + sy * camera.up);
  const bvh::Hit hit = bvh::closestHit(bvh, {.origin = camera.position, .direction = d});
  if (!hit.hit()) return std::nullopt;
  const glm::uvec3 t = scene.triangles[hit.primitive];
  const glm::vec3 a = scene.positions[t.x], b = scene.positions[t.y], c = scene.positions[t.z];
  glm::vec3 n = glm::cross(b - a, c - a);
  if (!(glm::length(n) > 0.0f)) return std::nullopt;
  n = glm::normalize(n);
  if (glm::dot(n, d) > 0.0f) n = -n; // the side the camera sees
  return GridHit{d, camera.position + hit.t * d, n, hit.primitive};
}

} // namespace obscura::render
