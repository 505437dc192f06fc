// shadow_pass.h — direct light at the primary hits into the basis buffers D_s (shadow.comp)
// [RTO §4.1 step 2, SPEC §1.3].
#pragma once
#include "render/passes/pixel_shading_pass.h"

namespace obscura::render {

class ShadowPass : public PixelShadingPass {
public:
  ShadowPass(const gpu::Context& context, const ShadingSpecialisation& s);
};

} // namespace obscura::render
