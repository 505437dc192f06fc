#include "render/denoise/edge_pass.h"

#include "denoise_edges.spv.h"
#include "render/obscurance_renderer.h"

namespace obscura::render {
namespace {
gpu::KernelDesc edgeKernelDesc(const SceneSpecialisation& scene) {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kEdgesBindingCount - gpu::kSceneBindingCount, gpu::BindingKind::StorageBuffer);
  gpu::KernelDesc desc{.name = "denoise.edges", .spirv = kSpirv_denoise_edges, .bindings = bindings,
                       .pushConstantBytes = sizeof(gpu::DenoiseEdgesPush), .specConstants = {}, .setCount = 1};
  scene.addTo(desc);
  return desc;
}
} // namespace

EdgePass::EdgePass(const gpu::Context& context, const SceneSpecialisation& scene)
    : context_(&context), scene_(scene), kernel_(context, edgeKernelDesc(scene)) {}

void EdgePass::bind(const ObscuranceRenderer& renderer, const DenoiseFrame& frame, std::uint32_t parity) {
  if (!(renderer.sceneKernels() == scene_)) {
    scene_ = renderer.sceneKernels();
    kernel_ = gpu::Kernel(*context_, edgeKernelDesc(scene_));
  }
  renderer.sceneBuffers().bindTo(kernel_, 0, &renderer.frame().status());
  kernel_.bind(gpu::kBindingEdgesParams, frame.params);
  kernel_.bind(gpu::kBindingEdgesGuide, frame.guide[parity].buffer());
  kernel_.bind(gpu::kBindingEdgesRemodulated, frame.remodulated);
  kernel_.bind(gpu::kBindingEdgesEmission, frame.emission);
  kernel_.bind(gpu::kBindingEdgesLightScales, renderer.lightScales());
  kernel_.bind(gpu::kBindingEdgesEmissions, renderer.composeEmissions());
  kernel_.bind(gpu::kBindingEdgesOut, frame.combined);
}

void EdgePass::record(const vk::raii::CommandBuffer& cmd, const DenoiseFrame& frame, const Dispatch& dispatch) const {
  const gpu::DenoiseEdgesPush push{.geometryRays = dispatch.geometryRays, .emitterRays = dispatch.emitterRays,
                                   .lightCount = dispatch.lights, .ownEmissionRays = dispatch.ownEmissionRays,
                                   .ambientLuminance = dispatch.ambientLuminance, .unused0 = 0u, .unused1 = 0u,
                                   .unused2 = 0u};
  dispatchImage(kernel_, cmd, frame, push, 0);
}

} // namespace obscura::render
