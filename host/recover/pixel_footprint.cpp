#include "recover/pixel_footprint.h"

#include <algorithm>
#include <utility>

#include "recover/recovery_scene.h"

namespace obscura::recover {

render::GridCamera pixelCamera(const scene::Camera& camera, int width, int height) {
  render::GridCamera view{camera.position, glm::normalize(camera.forward), camera.up, camera.yfov,
                          float(width) / float(height)};
  view.up = glm::cross(glm::normalize(glm::cross(view.forward, camera.up)), view.forward); // as projectToPixel
  return view;
}

bool PixelFootprints::whole(std::size_t p) const {
  const std::int32_t* points = object.data() + p * kPoints;
  return std::all_of(points, points + kPoints, [&](std::int32_t o) { return o == points[0]; });
}

PixelFootprints traceFootprints(const scene::Scene& room, render::RayBatch& rays, const scene::Camera& camera,
                                int width, int height) {
  const render::GridCamera view = pixelCamera(camera, width, height);
  const std::vector<std::uint32_t> objectOf = triangleObjects(room);
  PixelFootprints out;
  out.width = width;
  out.height = height;
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  out.object.assign(pixels * PixelFootprints::kPoints, -1);
  std::vector<bvh::Ray> cameraRays;
  cameraRays.reserve(pixels * PixelFootprints::kPoints);
  for (std::size_t p = 0; p < pixels; ++p) {
    const float x = float(p % std::size_t(width)), y = float(p / std::size_t(width));
    for (int k = 0; k < PixelFootprints::kPoints; ++k) {
      const float jx = (float(k % PixelFootprints::kGrid) + 0.5f) / float(PixelFootprints::kGrid);
      const float jy = (float(k / PixelFootprints::kGrid) + 0.5f) / float(PixelFootprints::kGrid);
      cameraRays.push_back(render::gridRay(view, (x + jx) / float(width), (y + jy) / float(height), 1));
    }
  }
  const std::vector<bvh::Hit> hits = rays.closest(cameraRays);
  for (std::size_t r = 0; r < hits.size(); ++r)
    if (render::gridHit(room, cameraRays[r], hits[r])) out.object[r] = std::int32_t(objectOf.at(hits[r].primitive));
  return out;
}

std::size_t mixFootprints(const PixelFootprints& footprints, const std::vector<std::int32_t>& object,
                          const std::vector<glm::vec3>& objectMeans, std::vector<glm::vec3>& reflectance) {
  const int w = footprints.width, h = footprints.height;
  const std::vector<glm::vec3> estimate = reflectance; // the whole pixels' own, before any is mixed
  std::vector<char> whole(estimate.size());
  for (std::size_t p = 0; p < whole.size(); ++p) whole[p] = footprints.whole(p);
  // rho_o near pixel (x, y): the mean of o's whole pixels in the window, else o's mean.
  const auto surfaceNear = [&](std::int32_t o, int x, int y) {
    glm::vec3 sum(0.0f);
    int n = 0;
    for (int v = std::max(0, y - kFootprintMixRadius); v <= std::min(h - 1, y + kFootprintMixRadius); ++v)
      for (int u = std::max(0, x - kFootprintMixRadius); u <= std::min(w - 1, x + kFootprintMixRadius); ++u) {
        const std::size_t q = std::size_t(v) * std::size_t(w) + std::size_t(u);
        if (whole[q] && footprints.object[q * PixelFootprints::kPoints] == o) {
          sum += estimate[q];
          ++n;
        }
      }
    return n >= kFootprintMixSupport ? sum / float(n) : objectMeans.at(std::size_t(o));
  };
  std::size_t mixed = 0;
  std::vector<std::pair<std::int32_t, int>> shares; // (object, points)
  for (std::size_t p = 0; p < estimate.size(); ++p) {
    if (object[p] < 0 || whole[p]) continue;
    shares.clear();
    for (int k = 0; k < PixelFootprints::kPoints; ++k) {
      const std::int32_t o = footprints.object[p * PixelFootprints::kPoints + std::size_t(k)];
      if (o < 0) continue; // nothing there: no light in the photograph, no reflectance in the mix
      auto it = std::find_if(shares.begin(), shares.end(), [&](const auto& s) { return s.first == o; });
      if (it == shares.end()) shares.push_back({o, 1});
      else ++it->second;
    }
    const int x = int(p % std::size_t(w)), y = int(p / std::size_t(w));
    glm::vec3 mix(0.0f);
    for (const auto& [o, points] : shares) mix += float(points) / float(PixelFootprints::kPoints) * surfaceNear(o, x, y);
    reflectance[p] = mix;
    ++mixed;
  }
  return mixed;
}

} // namespace obscura::recover
