#include "render/passes/obscurance_pass.h"

#include "obscurance.spv.h"

namespace obscura::render {

ObscurancePass::ObscurancePass(const gpu::Context& context, std::uint32_t bands)
    : PixelShadingPass(context, "obscurance", kSpirv_obscurance, bands, {.reflectors = true, .grey = true}) {}

} // namespace obscura::render
