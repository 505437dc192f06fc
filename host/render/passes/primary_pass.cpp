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
gpu::KernelDesc primaryKernelDesc(std::uint32_t bands) {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kPrimaryBindingCount - gpu::kSceneBindingCount,
                  gpu::BindingKind::StorageBuffer);
  return {.name = "primary", .spirv = kSpirv_primary, .bindings = bindings,
          .pushConstantBytes = sizeof(gpu::PrimaryPush), .setCount = bands};
}
} // namespace

PrimaryPass::PrimaryPass(const gpu::Context& context, std::uint32_t bands)
    : kernel_(context, primaryKernelDesc(bands)) {}

void PrimaryPass::bind(std::uint32_t band, const SceneBuffers& scene, const ObscuranceFrame& frame,
                       const gpu::Buffer& lightScales) {
  scene.bindTo(kernel_, band, &frame.status());
  const auto& b = frame.band(band);
  kernel_.bind(gpu::kBindingPrimaryGBuffer, b.gbuffer, band);
  kernel_.bind(gpu::kBindingPrimaryAovs, b.aovs, band);
  kernel_.bind(gpu::kBindingPrimaryLightScales, lightScales, band);
  kernel_.bind(gpu::kBindingPrimaryEmissionBasis, b.emissionBasis, band);
  kernel_.bind(gpu::kBindingPrimaryHitBounds, b.hitBounds, band);
  kernel_.bind(gpu::kBindingPrimaryDirty, b.dirty, band);
  kernel_.bind(gpu::kBindingPrimarySampleCounts, b.sampleCounts, band);
}

void PrimaryPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                         const gpu::GpuCamera& camera, std::uint32_t sampleIndex, std::uint32_t seed,
                         std::uint32_t lights, std::uint32_t flags, const ObscuranceFrame* dirtyOf) const {
  const FrameBand& rows = layout.bands[band];
  gpu::PrimaryPush push{.camera = camera,
                        .frame = glm::uvec4(layout.width, layout.height, sampleIndex, seed),
                        .band = glm::uvec4(rows.firstRow, rows.rows, lights, flags)};
  if (dirtyOf != nullptr) {
    kernel_.dispatchIndirect(cmd, dirtyOf->band(band).dirty, dirtyOf->dirtyListOffset(band), &push, band);
    return;
  }
  kernel_.dispatch(cmd, gpu::groupsFor(layout.width, gpu::kWorkgroupSizeX),
                   gpu::groupsFor(rows.rows, gpu::kWorkgroupSizeY), 1, &push, band);
}

} // namespace obscura::render
