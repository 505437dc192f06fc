// ray_tracer.h — traces a list of rays on the GPU with the production traversal (trace.comp).
// Used by `obscura bench-rays` and the traversal tests, so the benchmark measures tested code.
#pragma once
#include <span>
#include <vector>

#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "render/scene/scene_buffers.h"

namespace obscura::render {

enum class TraceMode : std::uint32_t { Closest = 0, Any = 1 };

struct TraceResult {
  std::vector<gpu::GpuHit> hits;
  std::vector<std::uint32_t> steps; // loop passes per ray, when asked for
  double gpuMs = 0.0;               // GPU time of the dispatches (timestamps), 0 if unavailable
};

class RayTracer {
public:
  RayTracer(const gpu::Context& context, const SceneBuffers& scene);

  TraceResult trace(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps = false);

private:
  TraceResult traceFitting(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps);

  const gpu::Context* context_;
  gpu::Kernel kernel_;      // the timed one
  gpu::Kernel stepsKernel_; // also records each ray's loop passes (compiled on first use)
  gpu::Timestamps timestamps_;
};

} // namespace obscura::render
