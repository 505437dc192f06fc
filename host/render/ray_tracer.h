// ray_tracer.h — traces a list of rays on the GPU with the production traversal (trace.comp).
// Used by `obscura bench-rays` and the traversal tests, so the benchmark measures tested code, and
// by the reach measurement (GpuRayBatch), whose rays an edit would otherwise wait for on the CPU.
#pragma once
#include <optional>
#include <span>
#include <vector>

#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::render {

enum class TraceMode : std::uint32_t { Closest = 0, Any = 1 };

struct TraceResult {
  std::vector<gpu::GpuHit> hits;
  std::vector<std::uint32_t> steps; // loop passes per ray, when asked for
  double gpuMs = 0.0;               // GPU time of the dispatches (timestamps), 0 if unavailable
  std::vector<double> repeatGpuMs;  // traceRepeated: each repeat's GPU time (the first is gpuMs)
};

// How trace.comp spreads rays over invocations (shared/host_device.h): the refilling loop of
// kTraceRaysPerLane rays per invocation on lavapipe, of kTraceGpuRaysPerLane on a GPU; one ray per
// invocation goes straight through traverseBvh.
struct TraceShape {
  std::uint32_t workgroupSize = gpu::kTraceWorkgroupSize;
  std::uint32_t raysPerLane = gpu::kTraceRaysPerLane;
  // The BVH read from its buffer bound as an SSBO, not through the texel view (the passes' path).
  bool bvhItemsFromStorage = false;
  // The binary traversal's closest-hit rays drop popped children beyond their hit
  // (kSpecConstantBinaryCullOnPop; off, as in the passes).
  bool binaryCullOnPop = false;
  static TraceShape forCpu() { return {}; }
  static TraceShape forGpu() { return {gpu::kTraceGpuWorkgroupSize, gpu::kTraceGpuRaysPerLane}; }
  // The binary traversal: one ray per invocation, straight through traverseBvh (what a pass's
  // ray gets); other shapes refill (lib/bvh_stream.glsl, traverseBinaryStream).
  static TraceShape forBinary() { return {gpu::kTraceBinaryWorkgroupSize, 1}; }
  // For the wide layout forCpu() on a CPU device, forGpu() otherwise; forBinary() for a binary one.
  static TraceShape forDevice(const gpu::Context& context, Traversal traversal);
};

class RayTracer {
public:
  // `shape` defaults to the device's (TraceShape::forDevice); a test may force either.
  // `compactStackVectors` (kSpecConstantCompactStack) defaults to what the scene's BVH needs; a
  // test may force the general kernel (0) or any compact stack (which throws where the BVH
  // could overflow it).
  RayTracer(const gpu::Context& context, const SceneBuffers& scene, std::optional<TraceShape> shape = {},
            std::optional<std::uint32_t> compactStackVectors = {});
  const TraceShape& shape() const { return shape_; }
  // The scene's buffers were made again or re-uploaded (a geometry edit): bind them anew. The
  // traversal and stack the kernel was made for must still hold (SceneBuffers::specialisation).
  void rebind();

  TraceResult trace(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps = false);
  // The same rays traced `repeats` times back to back in one submission, each repeat timed: a
  // GPU that idles between submissions (the upload, the read-back) drops its clocks, and a short
  // trace after such a pause ran 2-5x slower on an H200.
  TraceResult traceRepeated(std::span<const gpu::GpuRay> rays, TraceMode mode, std::uint32_t repeats,
                            bool recordSteps = false);

private:
  TraceResult traceFitting(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps,
                           std::uint32_t repeats);
  // The buffers of a trace of `rays` rays, kept from one trace to the next and grown when a trace
  // needs more (rebinding them): a renderer traces a few small sets per edit (the lights' reach),
  // and allocating device memory, staging and an extra submission for each cost an H200 ~4 ms.
  void reserve(std::size_t rays);

  const gpu::Context* context_;
  TraceShape shape_;
  const SceneBuffers* scene_;
  std::uint32_t compactStackVectors_;
  gpu::Kernel kernel_;                     // the timed one
  std::optional<gpu::Kernel> stepsKernel_; // also records each ray's loop passes (made on first use)
  gpu::Timestamps timestamps_;
  std::size_t capacity_ = 0;  // rays the buffers below hold
  gpu::TexelBuffer rayBuffer_, hitBuffer_, stepBuffer_;
  // Host memory the rays come from and the hits go to, copied in the trace's own submission.
  gpu::Buffer rayStaging_, hitReadback_, stepReadback_;
};

} // namespace obscura::render
