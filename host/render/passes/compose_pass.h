// compose_pass.h — the image from the basis buffers with the current emissions (compose.comp):
// C = sum_s E_s (D_s + M_s) + I_a(E) A (+ specular) [SPEC §3]. A light edit runs this pass alone.
#pragma once
#include <glm/glm.hpp>

#include "gpu/kernel.h"
#include "shared/host_device.h"
#include "render/frame/obscurance_frame.h"

namespace obscura::render {

class ComposePass {
public:
  ComposePass(const gpu::Context& context, std::uint32_t bands);

  // `emissions`: vec4[lights], the E_s to compose with (not the render-time normaliser).
  void bind(std::uint32_t band, const ObscuranceFrame& frame, const gpu::Buffer& emissions);
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              std::uint32_t lights, const glm::vec3& ambientIntensity,
              bool specular, std::uint32_t slots) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
