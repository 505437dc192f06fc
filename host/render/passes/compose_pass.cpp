#include "render/passes/compose_pass.h"

#include "compose.spv.h"

namespace obscura::render {

ComposePass::ComposePass(const gpu::Context& context, std::uint32_t bands)
    : kernel_(context, gpu::storageKernelDesc("compose", kSpirv_compose, gpu::kComposeBindingCount, sizeof(gpu::ComposePush),
                                              {gpu::kBindingComposeBasis, gpu::kBindingComposeAmbient,
                                               gpu::kBindingComposeEmissionBasis, gpu::kBindingComposeSpecularBasis,
                                               gpu::kBindingComposeSpecularAmbient},
                                              bands)) {}

void ComposePass::bind(std::uint32_t band, const ObscuranceFrame& frame, const gpu::Buffer& emissions) {
  const auto& b = frame.band(band);
  kernel_.bind(gpu::kBindingComposeBasis, b.basis, band);
  kernel_.bind(gpu::kBindingComposeAmbient, b.ambient, band);
  kernel_.bind(gpu::kBindingComposeEmissionBasis, b.emissionBasis, band);
  kernel_.bind(gpu::kBindingComposeEmissions, emissions, band);
  kernel_.bind(gpu::kBindingComposeOutput, b.composed, band);
  kernel_.bind(gpu::kBindingComposeSpecularBasis, b.specularBasis, band);
  kernel_.bind(gpu::kBindingComposeSpecularAmbient, b.specularAmbient, band);
  kernel_.bind(gpu::kBindingComposeSampleCounts, b.sampleCounts, band);
}

void ComposePass::record(const vk::raii::CommandBuffer& cmd, std::uint32_t band, const FrameLayout& layout,
                         std::uint32_t lights, const glm::vec3& ambientIntensity,
                         bool specular, std::uint32_t slots) const {
  const gpu::ComposePush push{.width = layout.width, .rows = layout.bands[band].rows, .lightCount = lights,
                              .slots = slots, .ambient = ambientIntensity, .specular = specular ? 1u : 0u};
  kernel_.dispatch(cmd, gpu::groupsFor(layout.bandPixels(band), gpu::kWorkgroupSize1D), 1, 1, push, band);
}

} // namespace obscura::render
