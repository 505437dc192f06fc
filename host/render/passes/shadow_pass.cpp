#include "render/passes/shadow_pass.h"

#include "shadow.spv.h"

namespace obscura::render {

ShadowPass::ShadowPass(const gpu::Context& context, std::uint32_t bands)
    : PixelShadingPass(context, "shadow", kSpirv_shadow, bands, {.perLight = true, .replayKeptRays = true}) {}

} // namespace obscura::render
