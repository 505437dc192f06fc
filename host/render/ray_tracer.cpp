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
    if (capacity_ == 0) continue;
    kernel->bind(gpu::kBindingPassFirst, rayBuffer_);
    kernel->bind(gpu::kBindingPassFirst + 1, hitBuffer_);
    kernel->bind(gpu::kBindingPassFirst + 2, stepBuffer_);
  }
}

void RayTracer::reserve(std::size_t rays) {
  if (rays <= capacity_) return;
  using Usage = vk::BufferUsageFlagBits;
  std::size_t capacity = 4096;
  while (capacity < rays) capacity *= 2;
  const std::size_t maxRays = context_->info().maxTexelBufferElements / 2;
  capacity = std::min(capacity, std::max(maxRays, rays));
  rayBuffer_ = gpu::TexelBuffer(*context_, capacity * sizeof(gpu::GpuRay), vk::Format::eR32G32B32A32Sfloat, {},
                                "trace.rays");
  hitBuffer_ = gpu::TexelBuffer(*context_, capacity * sizeof(gpu::GpuHit), vk::Format::eR32G32B32A32Sfloat,
                                Usage::eStorageTexelBuffer, "trace.hits");
  stepBuffer_ = gpu::TexelBuffer(*context_, capacity * 4ull, vk::Format::eR32Uint, Usage::eStorageTexelBuffer,
                                 "trace.steps");
  rayStaging_ = gpu::Buffer(*context_, capacity * sizeof(gpu::GpuRay), {}, "trace.rays.staging", gpu::Residence::Host);
  hitReadback_ = gpu::Buffer(*context_, capacity * sizeof(gpu::GpuHit), {}, "trace.hits.readback", gpu::Residence::Host);
  stepReadback_ = gpu::Buffer(*context_, capacity * 4ull, {}, "trace.steps.readback", gpu::Residence::Host);
  capacity_ = capacity;
  rebind();
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
  const auto n = static_cast<std::uint32_t>(rays.size());
  if (recordSteps && !stepsKernel_) {
    stepsKernel_.emplace(*context_, traceKernelDesc(shape_, true, compactStackVectors_, scene_->traversal()));
    rebind();
  }
  reserve(std::max<std::size_t>(n, 1));
  if (n) rayStaging_.upload(*context_, rays.data(), rays.size_bytes());
  gpu::Kernel& kernel = recordSteps ? *stepsKernel_ : kernel_;

  const std::string label = mode == TraceMode::Closest ? "trace.closest" : "trace.any";
  const std::uint32_t maxGroups = std::min(context_->info().maxComputeWorkGroupCount[0], 65535u);
  const std::uint32_t raysPerGroup = shape_.workgroupSize * shape_.raysPerLane;
  const std::uint32_t raysPerDispatch = maxGroups * raysPerGroup;
  auto repeatLabel = [&](std::uint32_t r) { return fmt::format("{}.{}", label, r); };
  std::vector<double> before(repeats, 0.0);
  for (std::uint32_t r = 0; r < repeats; ++r)
    if (timestamps_.totalsMs().contains(repeatLabel(r))) before[r] = timestamps_.totalsMs().at(repeatLabel(r));
  const vk::DeviceSize hitBytes = vk::DeviceSize(n) * sizeof(gpu::GpuHit), stepBytes = vk::DeviceSize(n) * 4;
  context_->submitAndWait([&](const vk::raii::CommandBuffer& cmd) {
    timestamps_.reset(cmd);
    if (n) {
      cmd.copyBuffer(rayStaging_.handle(), rayBuffer_.buffer().handle(), vk::BufferCopy{.size = rays.size_bytes()});
      const vk::MemoryBarrier uploaded{.srcAccessMask = vk::AccessFlagBits::eTransferWrite,
                                       .dstAccessMask = vk::AccessFlagBits::eShaderRead};
      cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, uploaded,
                          nullptr, nullptr);
    }
    const vk::MemoryBarrier written{.srcAccessMask = vk::AccessFlagBits::eShaderWrite,
                                    .dstAccessMask = vk::AccessFlagBits::eShaderWrite};
    const vk::MemoryBarrier toCopy{.srcAccessMask = vk::AccessFlagBits::eShaderWrite,
                                   .dstAccessMask = vk::AccessFlagBits::eTransferRead};
    for (std::uint32_t r = 0; r < repeats; ++r) {
      if (r > 0) // the repeats write the same hits
        cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader, {},
                            written, nullptr, nullptr);
      timestamps_.begin(cmd, repeatLabel(r));
      for (std::uint32_t first = 0; first < n; first += raysPerDispatch) {
        std::uint32_t count = std::min(raysPerDispatch, n - first);
        const gpu::TracePush push{.rayCount = n, .anyHit = static_cast<std::uint32_t>(mode), .unused = 0u, .firstRay = first};
        kernel.dispatch(cmd, gpu::groupsFor(count, raysPerGroup), 1, 1, push);
      }
      timestamps_.end(cmd, repeatLabel(r));
    }
    if (n == 0) return;
    // The hits (and steps) into host memory in the same submission: no second one to read back.
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eTransfer, {}, toCopy,
                        nullptr, nullptr);
    cmd.copyBuffer(hitBuffer_.buffer().handle(), hitReadback_.handle(), vk::BufferCopy{.size = hitBytes});
    if (recordSteps) cmd.copyBuffer(stepBuffer_.buffer().handle(), stepReadback_.handle(), vk::BufferCopy{.size = stepBytes});
    const vk::MemoryBarrier copied{.srcAccessMask = vk::AccessFlagBits::eTransferWrite,
                                   .dstAccessMask = vk::AccessFlagBits::eHostRead};
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eHost, {}, copied, nullptr,
                        nullptr);
  });
  timestamps_.collect();
  TraceResult result;
  for (std::uint32_t r = 0; r < repeats; ++r)
    result.repeatGpuMs.push_back(timestamps_.available() ? timestamps_.totalsMs().at(repeatLabel(r)) - before[r] : 0.0);
  result.gpuMs = result.repeatGpuMs.front();
  result.hits.resize(n);
  if (n) hitReadback_.download(*context_, result.hits.data(), hitBytes);
  if (recordSteps) {
    result.steps.resize(n);
    if (n) stepReadback_.download(*context_, result.steps.data(), stepBytes);
  }
  return result;
}

} // namespace obscura::render
