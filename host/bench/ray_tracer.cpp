#include "bench/ray_tracer.h"

#include <algorithm>

#include "trace.spv.h"

namespace obscura::render {

namespace {
gpu::KernelDesc traceKernelDesc() {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), 3, gpu::BindingKind::StorageBuffer); // rays, hits, steps
  return {.name = "trace",
          .spirv = kSpirv_trace,
          .bindings = bindings,
          .pushConstantBytes = sizeof(gpu::TracePush)};
}
} // namespace

RayTracer::RayTracer(const gpu::Context& context, const SceneBuffers& scene)
    : context_(&context), kernel_(context, traceKernelDesc()), timestamps_(context) {
  scene.bindTo(kernel_);
}

TraceResult RayTracer::trace(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps) {
  using Usage = vk::BufferUsageFlagBits;
  const auto n = static_cast<std::uint32_t>(rays.size());
  gpu::Buffer rayBuffer(*context_, rays.size_bytes(), Usage::eStorageBuffer, "trace.rays");
  rayBuffer.upload(*context_, rays);
  gpu::Buffer hitBuffer(*context_, n * sizeof(gpu::GpuHit), Usage::eStorageBuffer, "trace.hits");
  gpu::Buffer stepBuffer(*context_, recordSteps ? n * 4ull : 4ull, Usage::eStorageBuffer, "trace.steps");
  kernel_.bind(gpu::kBindingPassFirst, rayBuffer);
  kernel_.bind(gpu::kBindingPassFirst + 1, hitBuffer);
  kernel_.bind(gpu::kBindingPassFirst + 2, stepBuffer);

  const std::string label = mode == TraceMode::Closest ? "trace.closest" : "trace.any";
  const std::uint32_t maxGroups = std::min(context_->info().maxComputeWorkGroupCount[0], 65535u);
  const std::uint32_t raysPerDispatch = maxGroups * gpu::kWorkgroupSize1D;
  context_->submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    timestamps_.begin(cmd, label);
    for (std::uint32_t first = 0; first < n; first += raysPerDispatch) {
      std::uint32_t count = std::min(raysPerDispatch, n - first);
      gpu::TracePush push{.params = glm::uvec4(n, static_cast<std::uint32_t>(mode), recordSteps ? 1u : 0u, first)};
      kernel_.dispatch(cmd, gpu::groupsFor(count, gpu::kWorkgroupSize1D), 1, 1, &push);
    }
    timestamps_.end(cmd, label);
  });
  double before = timestamps_.totalsMs().contains(label) ? timestamps_.totalsMs().at(label) : 0.0;
  timestamps_.collect();
  TraceResult result;
  result.gpuMs = timestamps_.available() ? timestamps_.totalsMs().at(label) - before : 0.0;
  result.hits = hitBuffer.download<gpu::GpuHit>(*context_);
  if (recordSteps) result.steps = stepBuffer.download<std::uint32_t>(*context_);
  return result;
}

} // namespace obscura::render
