#include "render/scene_data/secondary_reflectors.h"

#include <algorithm>
#include <cmath>

namespace obscura::render {

namespace {

double triangleArea(const scene::Scene& scene, std::uint32_t triangle) {
  const glm::uvec3 t = scene.triangles[triangle];
  const glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

} // namespace

SecondaryReflectorMarks markSecondaryReflectors(const scene::Scene& scene, const std::vector<LightReach>& reach,
                                                double threshold, double totalArea, bool reachedAreas) {
  SecondaryReflectorMarks out;
  out.marked.assign(scene.triangles.size(), 0);
  auto areaOf = [&](const LightReach& r) { return reachedAreas && r.area > 0.0 ? r.area : totalArea; };
  for (const LightReach& r : reach) {
    if (r.landings == 0) continue;
    const double meanIrradiance = static_cast<double>(r.landings) / areaOf(r); // rays per unit area
    for (const auto& [triangle, rays] : r.landedTriangles) {
      if (triangle >= scene.triangles.size()) continue;
      const double area = triangleArea(scene, triangle);
      if (area > 0.0 && static_cast<double>(rays) / area >= threshold * meanIrradiance) out.marked[triangle] = 1;
    }
  }
  // r: per light, the unmarked surfaces' share of its landed light over their share of its area.
  double sum = 0.0;
  std::size_t lights = 0;
  for (const LightReach& r : reach) {
    if (r.landings == 0) continue;
    double markedRays = 0.0, markedArea = 0.0;
    for (const auto& [triangle, rays] : r.landedTriangles)
      if (triangle < scene.triangles.size() && out.marked[triangle]) {
        markedRays += rays;
        markedArea += triangleArea(scene, triangle);
      }
    const double unmarkedArea = std::max(1.0 - markedArea / areaOf(r), 1e-3);
    sum += (1.0 - markedRays / static_cast<double>(r.landings)) / unmarkedArea;
    ++lights;
  }
  out.unmarkedFirstBounce = lights > 0 ? static_cast<float>(sum / static_cast<double>(lights)) : 1.0f;
  out.count = static_cast<std::uint32_t>(std::count(out.marked.begin(), out.marked.end(), std::uint8_t{1}));
  return out;
}

glm::vec3 ambientShareBeyondFirstBounce(glm::vec3 averageReflectance, std::uint32_t depth) {
  glm::vec3 kappa(0.0f);
  for (int c = 0; c < 3; ++c) {
    const double r = std::clamp(static_cast<double>(averageReflectance[c]), 0.0, 0.999);
    const double series = depth == 0 ? 1.0 / (1.0 - r) : (1.0 - std::pow(r, depth - 1.0)) / (1.0 - r);
    kappa[c] = series > 1.0 ? static_cast<float>(1.0 - 1.0 / series) : 0.0f;
  }
  return kappa;
}

} // namespace obscura::render
