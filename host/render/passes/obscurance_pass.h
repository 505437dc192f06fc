// obscurance_pass.h — the obscurance rays at the primary hits into the ambient buffer A
// (obscurance.comp) [RTO §3, §4.1 step 3].
#pragma once
#include "render/passes/pixel_shading_pass.h"

namespace obscura::render {

class ObscurancePass : public PixelShadingPass {
public:
  ObscurancePass(const gpu::Context& context, const ShadingSpecialisation& s);
};

} // namespace obscura::render
