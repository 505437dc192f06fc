#include "render/gpu_ray_batch.h"

#include <limits>

namespace obscura::render {

namespace {
constexpr float kInfinity = std::numeric_limits<float>::infinity();
} // namespace

// One ray per invocation, straight through traverseBvh as a pass's rays go, on every device: a
// light's stages are a thousand to a few ten thousand rays, which lavapipe's refilling shape (64
// rays per lane, 2,048 per workgroup) would leave to one or two workgroups.
GpuRayBatch::GpuRayBatch(const gpu::Context& context, const SceneBuffers& scene, std::optional<TraceShape> shape)
    : tracer_(context, scene,
              shape ? *shape
                    : scene.traversal() == Traversal::Wide ? TraceShape{gpu::kTraceWorkgroupSize, 1u} : TraceShape::forBinary()) {}

TraceResult GpuRayBatch::trace(std::span<const bvh::Ray> rays, TraceMode mode) {
  std::vector<gpu::GpuRay> gpuRays;
  gpuRays.reserve(rays.size());
  for (const bvh::Ray& r : rays)
    gpuRays.push_back({glm::vec4(r.origin, r.tmin), glm::vec4(r.direction, r.tmax)});
  TraceResult result = tracer_.trace(gpuRays, mode);
  rays_ += rays.size();
  gpuMs_ += result.gpuMs;
  return result;
}

std::vector<bvh::Hit> GpuRayBatch::closest(std::span<const bvh::Ray> rays) {
  if (rays.empty()) return {};
  const TraceResult result = trace(rays, TraceMode::Closest);
  std::vector<bvh::Hit> hits(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const gpu::GpuHit& h = result.hits[i];
    // A ray the loop limiter cut off (kTruncatedHit, counted in the status buffer that the
    // renderer reports) counts as a miss: the measurement is an estimate of thousands of rays.
    if (h.primitive == gpu::kInvalidIndex || h.primitive == gpu::kTruncatedHit) continue;
    hits[i] = {.t = h.t, .u = h.u, .v = h.v, .primitive = h.primitive};
  }
  return hits;
}

std::vector<float> GpuRayBatch::blockedAt(std::span<const bvh::Ray> rays) {
  if (rays.empty()) return {};
  const TraceResult result = trace(rays, TraceMode::Any);
  std::vector<float> out(rays.size(), kInfinity);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const gpu::GpuHit& h = result.hits[i];
    if (h.primitive == gpu::kTruncatedHit) out[i] = rays[i].tmin; // cut off: taken as blocked
    else if (h.primitive != gpu::kInvalidIndex) out[i] = h.t;
  }
  return out;
}

} // namespace obscura::render
