#include "render/scene_data/ray_batch.h"

#include <limits>

namespace obscura::render {

std::vector<bvh::Hit> CpuRayBatch::closest(std::span<const bvh::Ray> rays) {
  std::vector<bvh::Hit> hits;
  hits.reserve(rays.size());
  for (const bvh::Ray& ray : rays) hits.push_back(bvh::closestHit(*bvh_, ray));
  return hits;
}

std::vector<float> CpuRayBatch::blockedAt(std::span<const bvh::Ray> rays) {
  std::vector<float> out;
  out.reserve(rays.size());
  for (const bvh::Ray& ray : rays) {
    float t = std::numeric_limits<float>::infinity();
    if (!bvh::anyHit(*bvh_, ray, &t)) t = std::numeric_limits<float>::infinity();
    out.push_back(t);
  }
  return out;
}

} // namespace obscura::render
