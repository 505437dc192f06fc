// gpu_ray_batch.h — the reach measurement's rays (scene_data/ray_batch.h) traced on the device
// with the renderer's own traversal and scene buffers (trace.comp through RayTracer): one
// submission per stage of a light's measurement, instead of the host's BVH.
//
// Not thread-safe (it submits to the context's queue): the renderer calls it on its own thread,
// between its passes.
#pragma once
#include "render/ray_tracer.h"
#include "render/scene_data/ray_batch.h"

namespace obscura::render {

class GpuRayBatch final : public RayBatch {
public:
  // `shape`: by default one ray per invocation, for a light's stages of a thousand to a few ten
  // thousand rays; sets of millions (recover's gather) take the device's (TraceShape::forDevice).
  GpuRayBatch(const gpu::Context& context, const SceneBuffers& scene, std::optional<TraceShape> shape = {});
  std::vector<bvh::Hit> closest(std::span<const bvh::Ray> rays) override;
  std::vector<float> blockedAt(std::span<const bvh::Ray> rays) override;
  // The scene's buffers changed (a geometry edit): see RayTracer::rebind.
  void rebind() { tracer_.rebind(); }
  // Rays traced and GPU time so far.
  std::uint64_t rays() const { return rays_; }
  double gpuMs() const { return gpuMs_; }

private:
  TraceResult trace(std::span<const bvh::Ray> rays, TraceMode mode);

  RayTracer tracer_;
  std::uint64_t rays_ = 0;
  double gpuMs_ = 0.0;
};

} // namespace obscura::render
