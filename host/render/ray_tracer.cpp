#include "render/ray_tracer.h"

#include <algorithm>

#include <fmt/core.h>

#include "trace.spv.h"

namespace obscura::render {

namespace {
gpu::KernelDesc traceKernelDesc(const TraceShape& shape, bool recordSteps, std::uint32_t compactStackVectors,
                                Traversal traversal) {
  auto bindings = sceneBindingKinds();
  // rays (two RGBA32F texels each), hits (one RGBA32F texel each), steps (R32UI): texel views,
  // which lavapipe reads and writes a texel per lane at a time (an SSBO: a word per lane at a time).
  bindings.push_back(gpu::BindingKind::UniformTexelBuffer);
  bindings.insert(bindings.end(), 2, gpu::BindingKind::StorageTexelBuffer);
  bindings.push_back(gpu::BindingKind::StorageBuffer); // the BVH's items, for bvhItemsFromStorage
  return {.name = "trace",
          .spirv = kSpirv_trace,
          .bindings = bindings,
          .pushConstantBytes = sizeof(gpu::TracePush),
          .specConstants = {{gpu::kSpecConstantTraceSteps, recordSteps ? 1u : 0u},
                            {gpu::kSpecConstantTraceRaysPerLane, shape.raysPerLane},
                            {gpu::kSpecConstantTraceWorkgroupSize, shape.workgroupSize},
                            {gpu::kSpecConstantCompactStack, compactStackVectors},
                            {gpu::kSpecConstantBvhItemsFromStorage, shape.bvhItemsFromStorage ? 1u : 0u},
                            {gpu::kSpecConstantBvhLayout, bvhLayoutOf(traversal)},
                            {gpu::kSpecConstantBinaryLoop, binaryWhileWhile(traversal) ? 1u : 0u},
                            {gpu::kSpecConstantBinaryCullOnPop, shape.binaryCullOnPop ? 1u : 0u}}};
}
} // namespace

TraceShape TraceShape::forDevice(const gpu::Context& context, Traversal traversal) {
  if (traversal != Traversal::Wide) return forBinary();
  return context.info().type == "cpu" ? forCpu() : forGpu();
}

RayTracer::RayTracer(const gpu::Context& context, const SceneBuffers& scene, std::optional<TraceShape> shape,
                     std::optional<std::uint32_t> compactStackVectors)
    : context_(&context), shape_(shape.value_or(TraceShape::forDevice(context, scene.traversal()))), scene_(&scene),
      compactStackVectors_(compactStackVectors.value_or(scene.compactStackVectors())),
      kernel_(context, traceKernelDesc(shape_, false, compactStackVectors_, scene.traversal())), timestamps_(context) {
  rebind();
}

void RayTracer::rebind() {
  for (gpu::Kernel* kernel : {&kernel_, stepsKernel_ ? &*stepsKernel_ : nullptr}) {
    if (!kernel) continue;
    scene_->bindTo(*kernel);
    kernel->bind(gpu::kBindingPassFirst + 3, scene_->bvhItemsBuffer());
  }
}

TraceResult RayTracer::trace(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps) {
  return traceRepeated(rays, mode, 1, recordSteps);
}

TraceResult RayTracer::traceRepeated(std::span<const gpu::GpuRay> rays, TraceMode mode, std::uint32_t repeats,
                                     bool recordSteps) {
  repeats = std::max(repeats, 1u);
  // Texel views hold at most maxTexelBufferElements texels (two per ray): larger sets go in parts.
  const std::size_t maxRays = context_->info().maxTexelBufferElements / 2;
  if (rays.size() <= maxRays) return traceFitting(rays, mode, recordSteps, repeats);
  TraceResult all;
  all.repeatGpuMs.assign(repeats, 0.0);
  for (std::size_t first = 0; first < rays.size(); first += maxRays) {
    TraceResult part =
        traceFitting(rays.subspan(first, std::min(maxRays, rays.size() - first)), mode, recordSteps, repeats);
    all.hits.insert(all.hits.end(), part.hits.begin(), part.hits.end());
    all.steps.insert(all.steps.end(), part.steps.begin(), part.steps.end());
    for (std::uint32_t r = 0; r < repeats; ++r) all.repeatGpuMs[r] += part.repeatGpuMs[r];
  }
  all.gpuMs = all.repeatGpuMs.front();
  return all;
}

TraceResult RayTracer::traceFitting(std::span<const gpu::GpuRay> rays, TraceMode mode, bool recordSteps,
                                    std::uint32_t repeats) {
  using Usage = vk::BufferUsageFlagBits;
  const auto n = static_cast<std::uint32_t>(rays.size());
  gpu::TexelBuffer rayBuffer(*context_, std::max<std::size_t>(rays.size_bytes(), sizeof(gpu::GpuRay)),
                             vk::Format::eR32G32B32A32Sfloat, {}, "trace.rays");
  if (n) rayBuffer.upload(*context_, rays.data(), rays.size_bytes());
  gpu::TexelBuffer hitBuffer(*context_, std::max(n, 1u) * sizeof(gpu::GpuHit), vk::Format::eR32G32B32A32Sfloat,
                             Usage::eStorageTexelBuffer, "trace.hits");
  gpu::TexelBuffer stepBuffer(*context_, recordSteps ? std::max(n, 1u) * 4ull : 4ull, vk::Format::eR32Uint,
                              Usage::eStorageTexelBuffer, "trace.steps");
  if (recordSteps && !stepsKernel_) {
    stepsKernel_.emplace(*context_, traceKernelDesc(shape_, true, compactStackVectors_, scene_->traversal()));
    rebind();
  }
  gpu::Kernel& kernel = recordSteps ? *stepsKernel_ : kernel_;
  kernel.bind(gpu::kBindingPassFirst, rayBuffer);
  kernel.bind(gpu::kBindingPassFirst + 1, hitBuffer);
  kernel.bind(gpu::kBindingPassFirst + 2, stepBuffer);

  const std::string label = mode == TraceMode::Closest ? "trace.closest" : "trace.any";
  const std::uint32_t maxGroups = std::min(context_->info().maxComputeWorkGroupCount[0], 65535u);
  const std::uint32_t raysPerGroup = shape_.workgroupSize * shape_.raysPerLane;
  const std::uint32_t raysPerDispatch = maxGroups * raysPerGroup;
  auto repeatLabel = [&](std::uint32_t r) { return fmt::format("{}.{}", label, r); };
  std::vector<double> before(repeats, 0.0);
  for (std::uint32_t r = 0; r < repeats; ++r)
    if (timestamps_.totalsMs().contains(repeatLabel(r))) before[r] = timestamps_.totalsMs().at(repeatLabel(r));
  context_->submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    for (std::uint32_t r = 0; r < repeats; ++r) {
      if (r > 0) { // the repeats write the same hits
        vk::MemoryBarrier barrier{.srcAccessMask = vk::AccessFlagBits::eShaderWrite,
                                  .dstAccessMask = vk::AccessFlagBits::eShaderWrite};
        cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                            barrier, nullptr, nullptr);
      }
      timestamps_.begin(cmd, repeatLabel(r));
      for (std::uint32_t first = 0; first < n; first += raysPerDispatch) {
        std::uint32_t count = std::min(raysPerDispatch, n - first);
        const gpu::TracePush push{.rayCount = n, .anyHit = static_cast<std::uint32_t>(mode), .unused = 0u, .firstRay = first};
        kernel.dispatch(cmd, gpu::groupsFor(count, raysPerGroup), 1, 1, push);
      }
      timestamps_.end(cmd, repeatLabel(r));
    }
  });
  timestamps_.collect();
  TraceResult result;
  for (std::uint32_t r = 0; r < repeats; ++r)
    result.repeatGpuMs.push_back(timestamps_.available() ? timestamps_.totalsMs().at(repeatLabel(r)) - before[r] : 0.0);
  result.gpuMs = result.repeatGpuMs.front();
  result.hits = hitBuffer.buffer().download<gpu::GpuHit>(*context_);
  result.hits.resize(n);
  if (recordSteps) result.steps = stepBuffer.buffer().download<std::uint32_t>(*context_);
  return result;
}

} // namespace obscura::render
