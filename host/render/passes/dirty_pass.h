// dirty_pass.h — the pixels a geometry edit can change (dirty.comp), and the clearing of their
// shading sums before they are retraced (clear.comp). With probing, dirty.comp runs twice: record
// marks the certain pixels and lists the candidates, the shading passes probe the candidates
// (ShadeDispatch::probe, lib/probe.glsl), and recordList lists the pixels found dirty.
#pragma once
#include <array>
#include <vector>

#include "gpu/kernel.h"
#include "render/frame/obscurance_frame.h"
#include "render/scene_data/light_set.h"
#include "scene/scene.h"
#include "shared/host_device.h"

namespace obscura::render {

// The pixel rectangle (x0, y0, x1, y1 inclusive) the box covers on screen: its 8 corners
// projected, rounded out to whole pixels. The whole frame when a corner lies behind the camera.
glm::uvec4 screenRect(const gpu::GpuCamera& camera, std::uint32_t width, std::uint32_t height, const scene::Bounds& box);

// Two vec4 per light for dirty.comp: (bounding sphere centre, radius), (direction, 1 if
// directional). An area light's sphere holds all its emitters.
std::vector<glm::vec4> lightBounds(const LightSet& lights);

class DirtyPass {
public:
  DirtyPass(const gpu::Context& context, std::uint32_t bands);
  void bind(std::uint32_t band, const ObscuranceFrame& frame, const gpu::Buffer& lightBounds);
  // Writes band `band`'s parameters (`changed`: up to kMaxChangedBoxes world boxes) for the next
  // record, each box grown by `pad` on every side (more than a ray origin's offset from its
  // surface). `all` marks every pixel. Segments to `tracedLight` are not tested: that light is
  // new, and its rays are traced at every pixel anyway (ObscuranceRenderer::addEmitter). `probe`:
  // the bounds only name candidates, which probing passes decide (then recordList follows).
  void prepare(std::uint32_t band, const FrameLayout& layout, const gpu::GpuCamera& camera,
               const std::vector<scene::Bounds>& changed, float pad, float dMax, std::uint32_t lights, bool all,
               std::uint32_t tracedLight = gpu::kInvalidIndex, bool probe = false);
  // Marks the band's pixels and lists the dirty ones (with `probe`, the candidates), and leaves the
  // changed boxes behind the list for the probing passes.
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout) const;
  // After the probing passes: lists the pixels they (or the boxes on screen) found dirty.
  void recordList(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout) const;
  void recordClear(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                   std::uint32_t lights, bool specular) const;

private:
  const gpu::Context* context_;
  gpu::Kernel mark_;
  gpu::Kernel clear_;
  std::vector<gpu::Buffer> params_; // one DirtyPush per band
  // Per band, the changed boxes as the probing passes read them (host_device.h, dirtyBoxesBase).
  std::vector<std::array<glm::vec4, 2 * gpu::kMaxChangedBoxes>> boxes_;
  void resetList(const vk::raii::CommandBuffer& cmd, std::uint32_t band) const;
  const ObscuranceFrame* frame_ = nullptr; // whose dirty buffers record resets (bind)
  const gpu::Buffer* lightBounds_ = nullptr; // copied behind the boxes for the probes (bind)
};

} // namespace obscura::render
