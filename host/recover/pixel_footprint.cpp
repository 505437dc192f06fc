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

std::vector<bool> PixelFootprints::wholePixels() const {
  std::vector<bool> out(std::size_t(width) * std::size_t(height));
  for (std::size_t p = 0; p < out.size(); ++p) out[p] = whole(p);
  return out;
}

namespace {

// The objects `view` sees at the centres of a grid x grid grid of cells over each of `pixels`:
// [i * grid^2 + point] for pixels[i], -1 where it sees nothing.
std::vector<std::int32_t> traceGrid(const scene::Scene& room, render::RayBatch& rays, const render::GridCamera& view,
                                    const std::vector<std::uint32_t>& objectOf, int width, int height,
                                    const std::vector<std::size_t>& pixels, int grid) {
  const std::size_t points = std::size_t(grid) * std::size_t(grid);
  std::vector<bvh::Ray> cameraRays;
  cameraRays.reserve(pixels.size() * points);
  for (const std::size_t p : pixels) {
    const float x = float(p % std::size_t(width)), y = float(p / std::size_t(width));
    for (std::size_t k = 0; k < points; ++k) {
      const float jx = (float(k % std::size_t(grid)) + 0.5f) / float(grid);
      const float jy = (float(k / std::size_t(grid)) + 0.5f) / float(grid);
      cameraRays.push_back(render::gridRay(view, (x + jx) / float(width), (y + jy) / float(height), 1));
    }
  }
  const std::vector<bvh::Hit> hits = rays.closest(cameraRays);
  std::vector<std::int32_t> object(hits.size(), -1);
  for (std::size_t r = 0; r < hits.size(); ++r)
    if (render::gridHit(room, cameraRays[r], hits[r])) object[r] = std::int32_t(objectOf.at(hits[r].primitive));
  return object;
}

} // namespace

PixelFootprints traceFootprints(const scene::Scene& room, render::RayBatch& rays, const scene::Camera& camera,
                                int width, int height, std::size_t* refined) {
  const render::GridCamera view = pixelCamera(camera, width, height);
  const std::vector<std::uint32_t> objectOf = triangleObjects(room);
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  std::vector<std::size_t> every(pixels);
  for (std::size_t p = 0; p < pixels; ++p) every[p] = p;
  constexpr std::size_t coarsePoints = std::size_t(PixelFootprints::kCoarseGrid) * PixelFootprints::kCoarseGrid;
  const std::vector<std::int32_t> coarse =
      traceGrid(room, rays, view, objectOf, width, height, every, PixelFootprints::kCoarseGrid);
  // -2 where a pixel's coarse points see more than one object, else the one they see.
  std::vector<std::int32_t> single(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::int32_t* points = coarse.data() + p * coarsePoints;
    single[p] = std::all_of(points, points + coarsePoints, [&](std::int32_t o) { return o == points[0]; }) ? points[0] : -2;
  }
  // The pixels an edge crosses or may cross: those whose coarse points see more than one object,
  // and of two side by side whose coarse points see one object each, a different one, both (the
  // edge between them lies in one). A pixel beside a mixed one is not traced again for it: an
  // edge that misses all its coarse points clips at most a strip of an eighth of it, which its own
  // estimate measures as well as a mix does (the staircase's RMSE 0.0407 over all pixels with its
  // 8 neighbours traced again for it, 0.0403 without, for half the fine rays). Every pixel whose
  // coarse points disagree (-2) is traced again, so none keeps -2 below.
  std::vector<std::size_t> nearEdge;
  const auto differs = [&](std::size_t p, std::size_t q) { return single[q] != -2 && single[q] != single[p]; };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t p = std::size_t(y) * std::size_t(width) + std::size_t(x);
      if (single[p] == -2 || (x > 0 && differs(p, p - 1)) || (x + 1 < width && differs(p, p + 1)) ||
          (y > 0 && differs(p, p - std::size_t(width))) || (y + 1 < height && differs(p, p + std::size_t(width))))
        nearEdge.push_back(p);
    }
  const std::vector<std::int32_t> fine =
      traceGrid(room, rays, view, objectOf, width, height, nearEdge, PixelFootprints::kGrid);
  PixelFootprints out;
  out.width = width;
  out.height = height;
  out.object.resize(pixels * PixelFootprints::kPoints);
  for (std::size_t p = 0; p < pixels; ++p)
    std::fill_n(out.object.begin() + std::ptrdiff_t(p * PixelFootprints::kPoints), PixelFootprints::kPoints, single[p]);
  for (std::size_t i = 0; i < nearEdge.size(); ++i)
    std::copy_n(fine.begin() + std::ptrdiff_t(i * PixelFootprints::kPoints), PixelFootprints::kPoints,
                out.object.begin() + std::ptrdiff_t(nearEdge[i] * PixelFootprints::kPoints));
  if (refined) *refined = nearEdge.size();
  return out;
}

std::size_t mixFootprints(const PixelFootprints& footprints, const std::vector<std::int32_t>& object,
                          const std::vector<glm::vec3>& objectMeans, std::vector<glm::vec3>& reflectance) {
  const int w = footprints.width, h = footprints.height;
  const std::vector<glm::vec3> estimate = reflectance; // the whole pixels' own, before any is mixed
  const std::vector<bool> whole = footprints.wholePixels();
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

std::size_t unmixFootprints(const PixelFootprints& footprints, const std::vector<std::int32_t>& object,
                            const std::vector<glm::vec3>& objectMeans, std::vector<glm::vec3>& reflectance,
                            std::vector<float>& weight) {
  std::size_t unmixed = 0;
  for (std::size_t p = 0; p < reflectance.size(); ++p) {
    const std::int32_t o = object[p];
    if (o < 0 || weight[p] <= 0.0f || footprints.whole(p)) continue;
    const std::int32_t* points = footprints.object.data() + p * PixelFootprints::kPoints;
    int own = 0;
    glm::vec3 others(0.0f); // sum_{j != o} a_j rho_j; points on nothing add no reflectance
    for (int k = 0; k < PixelFootprints::kPoints; ++k) {
      if (points[k] == o) ++own;
      else if (points[k] >= 0) others += objectMeans.at(std::size_t(points[k]));
    }
    const float share = float(own) / float(PixelFootprints::kPoints);
    others /= float(PixelFootprints::kPoints);
    if (share < kUnmixShare) {
      weight[p] = 0.0f;
      continue;
    }
    reflectance[p] = glm::clamp((reflectance[p] - others) / share, glm::vec3(0.0f), glm::vec3(1.0f));
    weight[p] *= share * share;
    ++unmixed;
  }
  return unmixed;
}

} // namespace obscura::recover
