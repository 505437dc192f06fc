#include "render/passes/dirty_pass.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "clear.spv.h"
#include "dirty.spv.h"

namespace obscura::render {

glm::uvec4 screenRect(const gpu::GpuCamera& camera, std::uint32_t width, std::uint32_t height,
                      const scene::Bounds& box) {
  const glm::uvec4 whole(0u, 0u, width - 1, height - 1);
  const glm::vec3 origin(camera.origin), forward(camera.forward), right(camera.right), up(camera.up);
  const float tanHalf = camera.origin.w, aspect = camera.forward.w;
  float u0 = 1e30f, v0 = 1e30f, u1 = -1e30f, v1 = -1e30f;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? box.hi.x : box.lo.x, (corner & 2) ? box.hi.y : box.lo.y,
                      (corner & 4) ? box.hi.z : box.lo.z);
    const glm::vec3 d = p - origin;
    const float z = glm::dot(d, forward);
    if (!(z > 1e-6f)) return whole; // behind or at the eye: it may cover anything
    // The inverse of cameraRayDirection (shaders/lib/camera.glsl).
    const float u = (glm::dot(d, right) / z / (tanHalf * aspect) + 1.0f) * 0.5f * static_cast<float>(width);
    const float v = (1.0f - glm::dot(d, up) / z / tanHalf) * 0.5f * static_cast<float>(height);
    u0 = std::min(u0, u);
    u1 = std::max(u1, u);
    v0 = std::min(v0, v);
    v1 = std::max(v1, v);
  }
  // A pixel x holds the samples in [x, x + 1): one more pixel each way absorbs rounding.
  const auto clampTo = [](float x, std::uint32_t size) {
    return static_cast<std::uint32_t>(std::clamp(x, 0.0f, static_cast<float>(size - 1)));
  };
  if (u1 < -1.0f || v1 < -1.0f || u0 > static_cast<float>(width) + 1.0f || v0 > static_cast<float>(height) + 1.0f)
    return glm::uvec4(1u, 1u, 0u, 0u); // off screen: an empty rectangle
  return glm::uvec4(clampTo(std::floor(u0) - 1.0f, width), clampTo(std::floor(v0) - 1.0f, height),
                    clampTo(std::floor(u1) + 1.0f, width), clampTo(std::floor(v1) + 1.0f, height));
}

std::vector<glm::vec4> lightBounds(const LightSet& lights) {
  std::vector<glm::vec4> out;
  for (const auto& l : lights.lights) {
    if (l.info.x == gpu::kLightArea) {
      scene::Bounds b;
      for (std::uint32_t e = l.info.y; e < l.info.y + l.info.z; ++e)
        for (const glm::vec4* v : {&lights.emitters[e].v0, &lights.emitters[e].v1, &lights.emitters[e].v2})
          b.grow(glm::vec3(*v));
      // A removed emitter (no area, never sampled) is a point at the origin.
      out.emplace_back(b.empty() ? glm::vec3(0.0f) : 0.5f * (b.lo + b.hi), 0.0f);
      out.emplace_back(b.empty() ? glm::vec3(0.0f) : 0.5f * (b.hi - b.lo), 0.0f);
    } else if (l.info.x == gpu::kLightDirectional) {
      out.emplace_back(0.0f, 0.0f, 0.0f, 1.0f);
      out.emplace_back(glm::vec3(l.direction), 0.0f);
    } else {
      out.emplace_back(glm::vec3(l.position), 0.0f);
      out.emplace_back(0.0f);
    }
  }
  if (out.empty()) out.emplace_back(0.0f);
  return out;
}

DirtyPass::DirtyPass(const gpu::Context& context, std::uint32_t bands)
    : context_(&context),
      mark_(context, gpu::storageKernelDesc("dirty", kSpirv_dirty, gpu::kDirtyBindingCount, sizeof(gpu::DirtyStagePush), bands)),
      clear_(context, gpu::storageKernelDesc("clear", kSpirv_clear, gpu::kClearBindingCount, sizeof(gpu::ClearPush), bands)) {
  for (std::uint32_t b = 0; b < bands; ++b)
    params_.emplace_back(context, sizeof(gpu::DirtyPush), vk::BufferUsageFlagBits::eStorageBuffer, "dirty.params");
  boxes_.resize(bands);
}

void DirtyPass::bind(std::uint32_t band, const ObscuranceFrame& frame, const gpu::Buffer& bounds) {
  const auto& b = frame.band(band);
  mark_.bind(gpu::kBindingDirtyParams, params_[band], band);
  mark_.bind(gpu::kBindingDirtyHitBounds, b.hitBounds, band);
  mark_.bind(gpu::kBindingDirtyLights, bounds, band);
  mark_.bind(gpu::kBindingDirtyMask, b.dirty, band);
  frame_ = &frame;
  lightBounds_ = &bounds;
  mark_.bind(gpu::kBindingDirtyStatus, frame.status(), band);
  clear_.bind(gpu::kBindingClearDirty, b.dirty, band);
  clear_.bind(gpu::kBindingClearBasis, b.basis.buffer(), band);
  clear_.bind(gpu::kBindingClearAmbient, b.ambient.buffer(), band);
  clear_.bind(gpu::kBindingClearSpecularBasis, b.specularBasis.buffer(), band);
  clear_.bind(gpu::kBindingClearSpecularAmbient, b.specularAmbient.buffer(), band);
}

void DirtyPass::prepare(std::uint32_t band, const FrameLayout& layout, const gpu::GpuCamera& camera,
                        const std::vector<scene::Bounds>& changed, float pad, float dMax, std::uint32_t lights,
                        bool all, std::uint32_t tracedLight, bool probe) {
  gpu::DirtyPush push{};
  push.width = layout.width;
  push.rows = layout.bands[band].rows;
  push.firstRow = layout.bands[band].firstRow;
  push.lightCount = lights;
  const bool tooMany = changed.size() > gpu::kMaxChangedBoxes;
  for (std::uint32_t i = 0; i < gpu::kMaxChangedBoxes; ++i) {
    if (i < changed.size() && !changed[i].empty()) {
      const scene::Bounds& box = changed[i];
      push.boxLo[i] = glm::vec4(box.lo - glm::vec3(pad), 1.0f);
      push.boxHi[i] = glm::vec4(box.hi + glm::vec3(pad), 0.0f);
      push.rects[i] = screenRect(camera, layout.width, layout.height, box);
    } else {
      push.boxLo[i] = glm::vec4(0.0f); // unused
      push.boxHi[i] = glm::vec4(0.0f);
      push.rects[i] = glm::uvec4(1u, 1u, 0u, 0u);
    }
  }
  push.dMax = dMax;
  push.all = all || tooMany ? 1u : 0u;
  push.tracedLight = tracedLight;
  push.probing = probe ? 1u : 0u;
  params_[band].upload(*context_, &push, sizeof(push));
  for (std::uint32_t i = 0; i < gpu::kMaxChangedBoxes; ++i) {
    boxes_[band][2 * i] = push.boxLo[i];
    boxes_[band][2 * i + 1] = push.boxHi[i];
  }
}

void DirtyPass::resetList(const vk::raii::CommandBuffer& cmd, std::uint32_t band) const {
  // The list starts empty: dispatching it indirectly runs (0, 1, 1) groups until dirty.comp appends.
  static constexpr std::array<std::uint32_t, gpu::kQueueHeader> kEmptyList = {0u, 1u, 1u, 0u};
  cmd.updateBuffer<std::uint32_t>(frame_->band(band).dirty.handle(), frame_->dirtyListOffset(band), kEmptyList);
}

void DirtyPass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout) const {
  resetList(cmd, band);
  const auto boxesAt = vk::DeviceSize(gpu::dirtyBoxesBase(static_cast<std::uint32_t>(layout.bandPixels(band)))) * 4;
  cmd.updateBuffer<glm::vec4>(frame_->band(band).dirty.handle(), boxesAt, boxes_[band]);
  const auto lightsAt = vk::DeviceSize(gpu::dirtyLightsBase(static_cast<std::uint32_t>(layout.bandPixels(band)))) * 4;
  const vk::DeviceSize lightBytes = std::min<vk::DeviceSize>(lightBounds_->size(), vk::DeviceSize(frame_->lightCapacity()) * 32);
  if (lightBytes > 0) cmd.copyBuffer(lightBounds_->handle(), frame_->band(band).dirty.handle(), vk::BufferCopy{0, lightsAt, lightBytes});
  gpu::computeBarrier(cmd);
  const gpu::DirtyStagePush push{.stage = gpu::kDirtyStageMark};
  mark_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, band);
}

void DirtyPass::recordList(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout) const {
  resetList(cmd, band);
  gpu::computeBarrier(cmd);
  const gpu::DirtyStagePush push{.stage = gpu::kDirtyStageList};
  mark_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, band);
}

void DirtyPass::recordClear(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                            std::uint32_t lights, bool specular) const {
  const gpu::ClearPush push{.width = layout.width, .rows = layout.bands[band].rows, .lightCount = lights,
                            .specular = specular ? 1u : 0u};
  clear_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, band);
}

} // namespace obscura::render
