// light_mix_pass.h — a light edit's display frame in one pass from the resolved transport:
// sum_s E_s T_s + I_a A_t, exposed and sRGB-encoded (lightmix.comp).
#pragma once
#include <glm/glm.hpp>

#include "gpu/kernel.h"
#include "render/frame/obscurance_frame.h"
#include "shared/host_device.h"

namespace obscura::render {

class LightMixPass {
public:
  LightMixPass(const gpu::Context& context, std::uint32_t bands);
  void bind(std::uint32_t band, const ObscuranceFrame& frame, const gpu::Buffer& emissions);
  void record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
              std::uint32_t lights, std::uint32_t slots, const glm::vec3& ambientIntensity,
              float exposureStops) const;

private:
  gpu::Kernel kernel_;
};

} // namespace obscura::render
