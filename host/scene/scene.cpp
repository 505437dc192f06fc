// scene.cpp — scene helpers shared by the loaders and the renderer.
#include "scene/scene.h"

#include <algorithm>
#include <cmath>

namespace obscura::scene {

Camera defaultCamera(const Bounds& bounds) {
  constexpr float kYfov = 0.7853982f; // 45 degrees
  Camera camera;
  camera.name = "default";
  camera.yfov = kYfov;
  camera.aspectRatio = 0.0f;
  // An empty or point-sized scene still gets a usable camera one unit back.
  const glm::vec3 centre = bounds.empty() ? glm::vec3(0.0f) : 0.5f * (bounds.lo + bounds.hi);
  const float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-3f);
  // The bounding sphere fits the vertical field of view when its tangent cone has half-angle
  // yfov/2: distance = r / sin(yfov/2). (The horizontal fit depends on the image aspect, which
  // the caller may narrow; vertical is the documented guarantee.)
  const float distance = bounds.empty() ? 1.0f : radius / std::sin(0.5f * kYfov);
  camera.position = centre + glm::vec3(0.0f, 0.0f, distance);
  camera.forward = glm::vec3(0.0f, 0.0f, -1.0f);
  camera.up = glm::vec3(0.0f, 1.0f, 0.0f);
  return camera;
}

} // namespace obscura::scene
