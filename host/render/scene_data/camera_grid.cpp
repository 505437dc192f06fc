#include "render/scene_data/camera_grid.h"

#include <cmath>

namespace obscura::render {

bvh::Ray gridRay(const GridCamera& camera, float gx, float gy, int grid) {
  const float tanHalf = std::tan(0.5f * camera.yfov);
  const glm::vec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
  const float g = static_cast<float>(grid);
  const float sx = (2.0f * gx / g - 1.0f) * tanHalf * camera.aspect;
  const float sy = (1.0f - 2.0f * gy / g) * tanHalf;
  return {.origin = camera.position, .direction = glm::normalize(camera.forward + sx * right + sy * camera.up)};
}

std::optional<GridHit> gridHit(const scene::Scene& scene, const bvh::Ray& ray, const bvh::Hit& hit) {
  if (!hit.hit()) return std::nullopt;
  const glm::uvec3 t = scene.triangles[hit.primitive];
  const glm::vec3 a = scene.positions[t.x], b = scene.positions[t.y], c = scene.positions[t.z];
  glm::vec3 n = glm::cross(b - a, c - a);
  if (!(glm::length(n) > 0.0f)) return std::nullopt;
  n = glm::normalize(n);
  const glm::vec3 d = ray.direction;
  if (glm::dot(n, d) > 0.0f) n = -n; // the side the camera sees
  return GridHit{d, ray.origin + hit.t * d, n, hit.primitive};
}

std::optional<GridHit> firstHitThroughGrid(const scene::Scene& scene, const bvh::Bvh& bvh, const GridCamera& camera,
                                           float gx, float gy, int grid) {
  const bvh::Ray ray = gridRay(camera, gx, gy, grid);
  return gridHit(scene, ray, bvh::closestHit(bvh, ray));
}

} // namespace obscura::render
