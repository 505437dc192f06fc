// primary_pass.h — camera rays to the G-buffer and the AOV accumulation (primary.comp).
#pragma once
#include <cstdint>
#include <functional>

#include "gpu/kernel.h"
#include "gpu/timestamps.h"
#include "render/scene/scene_buffers.h"
#include "scene/scene.h"

namespace obscura::render {

// Pinhole camera for an image of width x height. The image's aspect ratio wins over the camera's
// (the caller chooses the image size from the camera's aspect when the user gave none).
gpu::GpuCamera gpuCamera(const scene::Camera& camera, std::uint32_t width, std::uint32_t height);

class PrimaryPass {
public:
  PrimaryPass(const gpu::Context& context, const SceneBuffers& scene, std::uint32_t width,
              std::uint32_t height);

  // Records the dispatch of sample `sampleIndex` (0 restarts the accumulation).
  void record(const vk::raii::CommandBuffer& cmd, const gpu::GpuCamera& camera,
              std::uint32_t sampleIndex, std::uint32_t seed) const;

  const gpu::Buffer& gbuffer() const { return gbuffer_; }
  const gpu::Buffer& aovs() const { return aovs_; }
  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }

  // Device memory that a pass of this size needs, to refuse absurd resolutions up front.
  static std::uint64_t bytesNeeded(std::uint32_t width, std::uint32_t height);

private:
  std::uint32_t width_, height_;
  gpu::Kernel kernel_;
  gpu::Buffer gbuffer_;
  gpu::Buffer aovs_;
};

} // namespace obscura::render
