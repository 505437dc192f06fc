#include "render/passes/shadow_pass.h"

#include "shadow.spv.h"

namespace obscura::render {

ShadowPass::ShadowPass(const gpu::Context& context, const ShadingSpecialisation& s)
    : PixelShadingPass(context, "shadow", kSpirv_shadow, s, {.perLight = true, .replayKeptRays = true}) {}

} // namespace obscura::render
