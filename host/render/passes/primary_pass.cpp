#include "render/passes/primary_pass.h"

#include <bit>
#include <cmath>

#include "primary.spv.h"

namespace obscura::render {

gpu::GpuCamera gpuCamera(const scene::Camera& camera, std::uint32_t width, std::uint32_t height,
                         std::uint32_t backgroundLight) {
  glm::vec3 forward = glm::normalize(camera.forward);
  glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  glm::vec3 up = glm::cross(right, forward);
  float aspect = static_cast<float>(width) / static_cast<float>(height);
  return {.origin = glm::vec4(camera.position, std::tan(camera.yfov * 0.5f)),
          .forward = glm::vec4(forward, aspect),
          .right = glm::vec4(right, 0.0f),
          .up = glm::vec4(up, std::bit_cast<float>(backgroundLight))};
}

namespace {
// Variant `v`: bit 0 the AOV accumulators, bit 1 the emission rays. Compiled on first use (a render
// dispatches one or two of the four; each is an LLVM compile of the shader on lavapipe).
gpu::KernelDesc primaryKernelDesc(std::uint32_t bands, std::uint32_t v, const SceneSpecialisation& scene,
                                  bool hitBounds) {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kPrimaryBindingCount - gpu::kSceneBindingCount,
                  gpu::BindingKind::StorageBuffer);
  gpu::KernelDesc desc{.name = "primary", .spirv = kSpirv_primary, .bindings = bindings,
                       .pushConstantBytes = sizeof(gpu::PrimaryPush),
                       .specConstants = {{gpu::kSpecConstantPrimaryAovs, v & 1u},
                                         {gpu::kSpecConstantEmissionRays, (v >> 1) & 1u},
                                         {gpu::kSpecConstantPrimaryHitBounds, hitBounds ? 1u : 0u}},
                       .setCount = bands};
  scene.addTo(desc);
  return desc;
}
} // namespace

PrimaryPass::PrimaryPass(const gpu::Context& context, std::uint32_t bands, const SceneSpecialisation& scene,
                         bool hitBounds)
    : kernels_{gpu::Kernel(context, primaryKernelDesc(bands, 0u, scene, hitBounds)),
               gpu::Kernel(context, primaryKernelDesc(bands, 1u, scene, hitBounds)),
               gpu::Kernel(context, primaryKernelDesc(bands, 2u, scene, hitBounds)),
               gpu::Kernel(context, primaryKernelDesc(bands, 3u, scene, hitBounds))} {}

const gpu::Kernel& PrimaryPass::kernelFor(std::uint32_t flags) const {
  const bool sums = (flags & gpu::kPrimaryFlagGBufferOnly) == 0;
  const bool aovs = sums && (flags & gpu::kPrimaryFlagNoAovs) == 0;
  const bool emissionRays = sums && (flags >> gpu::kPrimaryEmissionSamplesShift) > 1u;
  return kernels_[(aovs ? 1u : 0u) | (emissionRays ? 2u : 0u)];
}

void PrimaryPass::bind(std::uint32_t band, const SceneBuffers& scene, const ObscuranceFrame& frame,
                       const gpu::Buffer& lightScales) {
  const auto& b = frame.band(band);
  for (gpu::Kernel& kernel : kernels_) {
    scene.bindTo(kernel, band, &frame.status());
    kernel.bind(gpu::kBindingPrimaryGBuffer, b.gbuffer.buffer(), band);
    kernel.bind(gpu::kBindingPrimaryAovs, b.aovs, band);
    kernel.bind(gpu::kBindingPrimaryLightScales, lightScales, band);
    kernel.bind(gpu::kBindingPrimaryEmissionBasis, b.emissionBasis.buffer(), band);
    kernel.bind(gpu::kBindingPrimaryHitBounds, b.hitBounds, band);
    kernel.bind(gpu::kBindingPrimaryDirty, b.dirty, band);
    kernel.bind(gpu::kBindingPrimarySampleCounts, b.sampleCounts, band);
  }
}

void PrimaryPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                         const gpu::GpuCamera& camera, Sample sample, std::uint32_t seed,
                         std::uint32_t lights, std::uint32_t flags, const ObscuranceFrame* dirtyOf) const {
  const FrameBand& rows = layout.bands[band];
  // The camera sees the whole image (a tile's rows are rows of it).
  gpu::PrimaryPush push{.camera = camera,
                        .frame = glm::uvec4(layout.width, layout.imageHeight, sample.index, seed),
                        .band = glm::uvec4(rows.firstRow, rows.rows, lights, flags),
                        .accumulation = glm::uvec4(sample.first, 0u, 0u, 0u)};
  const gpu::Kernel& kernel = kernelFor(flags);
  if (dirtyOf != nullptr) {
    kernel.dispatchIndirect(cmd, dirtyOf->band(band).dirty, dirtyOf->dirtyListOffset(band), &push, band);
    return;
  }
  kernel.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                   gpu::groupsFor(rows.rows, gpu::kWorkgroupSizeY), 1, &push, band);
}

} // namespace obscura::render
