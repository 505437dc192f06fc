#include "render/passes/primary_pass.h"

#include <cmath>

#include "primary.spv.h"

namespace obscura::render {

gpu::GpuCamera gpuCamera(const scene::Camera& camera, std::uint32_t width, std::uint32_t height) {
  glm::vec3 forward = glm::normalize(camera.forward);
  glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  glm::vec3 up = glm::cross(right, forward);
  float aspect = static_cast<float>(width) / static_cast<float>(height);
  return {.origin = glm::vec4(camera.position, std::tan(camera.yfov * 0.5f)),
          .forward = glm::vec4(forward, aspect),
          .right = glm::vec4(right, 0.0f),
          .up = glm::vec4(up, 0.0f)};
}

namespace {
gpu::KernelDesc primaryKernelDesc() {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), 2, gpu::BindingKind::StorageBuffer); // gbuffer, aovs
  return {.name = "primary", .spirv = kSpirv_primary, .bindings = bindings,
          .pushConstantBytes = sizeof(gpu::PrimaryPush)};
}
} // namespace

std::uint64_t PrimaryPass::bytesNeeded(std::uint32_t width, std::uint32_t height) {
  std::uint64_t pixels = std::uint64_t(width) * height;
  return pixels * (sizeof(gpu::GBufferTexel) + gpu::kAovSlots * gpu::kAccumulatorVec4s * sizeof(glm::vec4));
}

PrimaryPass::PrimaryPass(const gpu::Context& context, const SceneBuffers& scene, std::uint32_t width,
                         std::uint32_t height)
    : width_(width), height_(height), kernel_(context, primaryKernelDesc()),
      gbuffer_(context, std::uint64_t(width) * height * sizeof(gpu::GBufferTexel),
               vk::BufferUsageFlagBits::eStorageBuffer, "primary.gbuffer"),
      aovs_(context, std::uint64_t(width) * height * gpu::kAovSlots * gpu::kAccumulatorVec4s * sizeof(glm::vec4),
            vk::BufferUsageFlagBits::eStorageBuffer, "primary.aovs") {
  scene.bindTo(kernel_);
  kernel_.bind(gpu::kBindingPassFirst, gbuffer_);
  kernel_.bind(gpu::kBindingPassFirst + 1, aovs_);
}

void PrimaryPass::record(const vk::raii::CommandBuffer& cmd, const gpu::GpuCamera& camera,
                         std::uint32_t sampleIndex, std::uint32_t seed) const {
  gpu::PrimaryPush push{.camera = camera, .frame = glm::uvec4(width_, height_, sampleIndex, seed)};
  kernel_.dispatch(cmd, gpu::groupsFor(width_, gpu::kWorkgroupSizeX), gpu::groupsFor(height_, gpu::kWorkgroupSizeY),
                   1, &push);
}

} // namespace obscura::render
