// camera_grid.h — the first surface a camera sees through a point of a grid over its image. The
// CPU estimates fitted to one view sample the view this way: the default dmax (free_path.h) and the
// seen I_a (reached_surfaces.h).
#pragma once
#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "scene/scene.h"

namespace obscura::render {

struct GridCamera {
  glm::vec3 position{0.0f}, forward{0.0f, 0.0f, -1.0f}, up{0.0f, 1.0f, 0.0f};
  float yfov = 0.8f, aspect = 1.0f;
};

struct GridHit {
  glm::vec3 direction;     // of the camera ray
  glm::vec3 position;      // where it hit
  glm::vec3 normal;        // the triangle's geometric normal, on the side the camera sees
  std::uint32_t primitive; // the triangle
};

// The camera ray through (gx, gy) of a grid x grid over the image (cell (x, y) spans
// [x, x + 1) x [y, y + 1), y down).
bvh::Ray gridRay(const GridCamera& camera, float gx, float gy, int grid);
// What `ray` found, as a GridHit; none for a miss or a degenerate triangle.
std::optional<GridHit> gridHit(const scene::Scene& scene, const bvh::Ray& ray, const bvh::Hit& hit);
// gridRay's first hit in `bvh`.
std::optional<GridHit> firstHitThroughGrid(const scene::Scene& scene, const bvh::Bvh& bvh, const GridCamera& camera,
                                           float gx, float gy, int grid);

} // namespace obscura::render
