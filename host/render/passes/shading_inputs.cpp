#include "render/passes/shading_inputs.h"

namespace obscura::render {

ShadingSpecialisation shadingSpecialisation(std::uint32_t bands, bool spatialSampling, std::uint32_t lightCapacity,
                                            const SceneSpecialisation& scene) {
  return {.bands = bands,
          .flatLightSelection = spatialSampling && lightCapacity <= gpu::kMaxSpatialLights,
          .scene = scene};
}

gpu::KernelDesc shadingKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s) {
  auto bindings = sceneBindingKinds();
  bindings.insert(bindings.end(), gpu::kShadingBindingCount - gpu::kSceneBindingCount, gpu::BindingKind::StorageBuffer);
  bindings[gpu::kBindingGBuffer] = bindings[gpu::kBindingLights] = bindings[gpu::kBindingEmitters] =
      gpu::BindingKind::UniformTexelBuffer;
  bindings[gpu::kBindingBasis] = bindings[gpu::kBindingAmbient] = bindings[gpu::kBindingSpecularBasis] =
      bindings[gpu::kBindingSpecularAmbient] = gpu::BindingKind::StorageTexelBuffer;
  gpu::KernelDesc desc{.name = name, .spirv = spirv, .bindings = bindings, .pushConstantBytes = sizeof(gpu::ShadePush),
                       .setCount = s.bands};
  if (s.flatLightSelection) desc.specConstants.push_back({.id = gpu::kSpecConstantFlatLightSelection, .value = 1u});
  s.scene.addTo(desc);
  return desc;
}

gpu::KernelDesc probingKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s) {
  gpu::KernelDesc desc = shadingKernelDesc(name, spirv, s);
  desc.name += ".probe";
  desc.specConstants.push_back({.id = gpu::kSpecConstantProbe, .value = 1u});
  return desc;
}

gpu::KernelDesc reflectorKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s) {
  gpu::KernelDesc desc = shadingKernelDesc(name, spirv, s);
  desc.name += ".reflectors";
  desc.specConstants.push_back({.id = gpu::kSpecConstantReflectors, .value = 1u});
  return desc;
}

gpu::KernelDesc greyObscuranceKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s) {
  gpu::KernelDesc desc = shadingKernelDesc(name, spirv, s);
  desc.name += ".grey";
  desc.specConstants.push_back({.id = gpu::kSpecConstantGreyObscurance, .value = 1u});
  return desc;
}

gpu::KernelDesc perLightKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s) {
  gpu::KernelDesc desc = shadingKernelDesc(name, spirv, s);
  desc.name += ".perlight";
  desc.specConstants.push_back({.id = gpu::kSpecConstantPerLight, .value = 1u});
  return desc;
}

gpu::KernelDesc replayingKeptRaysKernelDesc(gpu::KernelDesc desc) {
  desc.name += ".replay";
  desc.specConstants.push_back({.id = gpu::kSpecConstantReplayRays, .value = 1u});
  return desc;
}

void bindShadingInputs(gpu::Kernel& kernel, std::uint32_t band, const ShadingInputs& in) {
  in.scene.bindTo(kernel, band, &in.frame.status());
  const auto& b = in.frame.band(band);
  kernel.bind(gpu::kBindingGBuffer, b.gbuffer, band);
  kernel.bind(gpu::kBindingLights, in.lights.lights, band);
  kernel.bind(gpu::kBindingEmitters, in.lights.emitters, band);
  kernel.bind(gpu::kBindingLightTree, in.lights.tree, band);
  kernel.bind(gpu::kBindingBasis, b.basis, band);
  kernel.bind(gpu::kBindingAmbient, b.ambient, band);
  kernel.bind(gpu::kBindingSpecularBasis, b.specularBasis, band);
  kernel.bind(gpu::kBindingSpecularAmbient, b.specularAmbient, band);
  kernel.bind(gpu::kBindingSpecularQueue, b.queue, band);
  kernel.bind(gpu::kBindingSpecularPaths, b.specularPaths, band);
  kernel.bind(gpu::kBindingLightScales, in.lights.scales, band);
  kernel.bind(gpu::kBindingDirty, b.dirty, band);
  kernel.bind(gpu::kBindingHitBounds, b.hitBounds, band);
  kernel.bind(gpu::kBindingPathHits, b.pathHits, band);
  kernel.bind(gpu::kBindingKeptShadowRays, b.shadowRays, band);
}

gpu::ShadePush packShadePush(const ShadeSample& sample, const ShadeDispatch& dispatch, const FrameLayout& layout,
                             std::uint32_t band, std::uint32_t pathDepth) {
  const std::uint32_t renderFlags = (sample.systematic ? gpu::kFlagSystematic : 0u) |
                                    (sample.colourBleeding ? gpu::kFlagBleed : 0u) |
                                    (sample.areaLightSampling ? gpu::kFlagAreaLightSampling : 0u) |
                                    (sample.glossyMis ? gpu::kFlagGlossyMis : 0u) |
                                    (sample.secondaryReflectors ? gpu::kFlagSecondaryReflectors : 0u) |
                                    (sample.vertexRaysByThroughput ? gpu::kFlagVertexRaysByThroughput : 0u) |
                                    (sample.darkEscapes ? gpu::kFlagDarkEscapes : 0u);
  const std::uint32_t dispatchFlags = (dispatch.dirtyOnly ? gpu::kShadeFlagDirtyOnly : 0u) |
                                      (dispatch.oneLight() ? gpu::kShadeFlagPerLight : 0u) |
                                      (dispatch.noDirect ? gpu::kShadeFlagNoDirect : 0u) |
                                      (dispatch.probe ? gpu::kShadeFlagProbe : 0u) |
                                      (dispatch.keptRays ? gpu::kShadeFlagKeptRays : 0u);
  return {.width = sample.width, .height = sample.height, .sampleIndex = sample.sample, .seed = sample.seed,
          .lightCount = sample.lights, .shadowRays = sample.shadowRays, .obscuranceRays = sample.obscuranceRays,
          .renderFlags = renderFlags,
          .dMax = sample.dMax, .tau = sample.tau, .rhoKind = static_cast<float>(sample.rho),
          .maxDepth = static_cast<float>(sample.maxDepth),
          .averageReflectance = sample.averageReflectance, .pathDepth = static_cast<float>(pathDepth),
          .eye = sample.eye, .sceneSize = sample.sceneSize,
          .firstRow = layout.bands[band].firstRow, .rows = layout.bands[band].rows, .dispatchFlags = dispatchFlags,
          // The light word is read only with kShadeFlagPerLight; 0 otherwise.
          .light = dispatch.oneLight() ? dispatch.light : 0u,
          .kappa = sample.kappa, .unmarkedFirstBounce = sample.unmarkedFirstBounce};
}

} // namespace obscura::render
