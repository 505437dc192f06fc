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

const gpu::Kernel& PrimaryPass::kernelFor(const Dispatch& dispatch) const {
  const bool sums = !dispatch.gbufferOnly;
  const bool aovs = sums && dispatch.aovs;
  const bool emissionRays = sums && dispatch.emissionSamples > 1u;
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
    kernel.bind(gpu::kBindingPrimaryEmitterEdges, b.emitterEdges, band);
  }
}

void PrimaryPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const ObscuranceFrame& frame,
                         const gpu::GpuCamera& camera, const Dispatch& dispatch) const {
  const FrameLayout& layout = frame.layout();
  const FrameBand& rows = layout.bands[band];
  // The emission rays go with a dispatch that accumulates.
  const std::uint32_t emissionSamples = dispatch.gbufferOnly || dispatch.emissionSamples <= 1u ? 0u : dispatch.emissionSamples;
  const std::uint32_t flags = (dispatch.gbufferOnly ? gpu::kPrimaryFlagGBufferOnly : 0u) |
                              // (a dispatch that sums nothing keeps no AOVs either way)
                              (dispatch.aovs || dispatch.gbufferOnly ? 0u : gpu::kPrimaryFlagNoAovs) |
                              (dispatch.dirtyOnly ? gpu::kPrimaryFlagDirtyOnly : 0u) |
                              (dispatch.emissionAtEdges ? gpu::kPrimaryFlagEmissionAtEdges : 0u) |
                              (emissionSamples << gpu::kPrimaryEmissionSamplesShift);
  // The camera sees the whole image (a tile's rows are rows of it).
  const gpu::PrimaryPush push{.camera = camera, .width = layout.width, .height = layout.imageHeight,
                              .sampleIndex = dispatch.sample, .seed = dispatch.seed,
                              .firstRow = rows.firstRow, .rows = rows.rows, .lightCount = dispatch.lights,
                              .flags = flags, .firstSample = dispatch.firstSample,
                              .unused0 = 0u, .unused1 = 0u, .unused2 = 0u};
  const gpu::Kernel& kernel = kernelFor(dispatch);
  if (dispatch.dirtyOnly) {
    kernel.dispatchIndirect(cmd, frame.band(band).dirty, frame.dirtyListOffset(band), push, band);
    return;
  }
  kernel.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                  gpu::groupsFor(rows.rows, gpu::kWorkgroupSizeY), 1, push, band);
}

} // namespace obscura::render
