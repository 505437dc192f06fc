// ray_batch.h — how the reach measurement (reached_surfaces.h) traces its rays: every ray of one
// stage at once, so that a GPU traces them in one dispatch. An edit that adds a light or moves an
// object waits for these rays (tens of thousands per light): on the CPU BVH they were 30-40 ms of
// host work per light on an H200's host, on the GPU's own traversal a fraction of a millisecond
// (GpuRayBatch, render/gpu_ray_batch.h). CpuRayBatch is the twin the tests hold it to.
#pragma once
#include <span>
#include <vector>

#include "bvh/bvh.h"

namespace obscura::render {

class RayBatch {
public:
  virtual ~RayBatch() = default;
  // The closest hit of every ray in (tmin, tmax] (bvh::closestHit's rules): t and primitive;
  // primitive kInvalidIndex for a miss.
  virtual std::vector<bvh::Hit> closest(std::span<const bvh::Ray> rays) = 0;
  // Whether anything lies in (tmin, tmax) of every ray: where along it the first hit found is
  // (not necessarily the closest), infinity where nothing is.
  virtual std::vector<float> blockedAt(std::span<const bvh::Ray> rays) = 0;
};

// The CPU's traversal (bvh::closestHit, bvh::anyHit) over a BVH that outlives it.
class CpuRayBatch final : public RayBatch {
public:
  explicit CpuRayBatch(const bvh::Bvh& bvh) : bvh_(&bvh) {}
  std::vector<bvh::Hit> closest(std::span<const bvh::Ray> rays) override;
  std::vector<float> blockedAt(std::span<const bvh::Ray> rays) override;

private:
  const bvh::Bvh* bvh_;
};

} // namespace obscura::render
