#include "render/passes/obscurance_pass.h"

#include "obscurance.spv.h"

namespace obscura::render {

ObscurancePass::ObscurancePass(const gpu::Context& context, const ShadingSpecialisation& s)
    : PixelShadingPass(context, "obscurance", kSpirv_obscurance, s, {.reflectors = true, .grey = true}) {}

} // namespace obscura::render
