// shading_inputs.h — what the shading passes (shadow, obscurance, specular) bind: the scene,
// the lights, and one band of the frame (shaders/lib/shading_bindings.glsl, bindings 0..17).
#pragma once
#include <span>

#include "gpu/kernel.h"
#include "render/frame/obscurance_frame.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::render {

struct LightBuffers {
  gpu::TexelBuffer lights;   // GpuLight[] (RGBA32F texels: shaders/lib/light_bindings.glsl)
  gpu::TexelBuffer emitters; // GpuEmitter[] (the same)
  gpu::Buffer scales;        // vec4[]: the render-time E_s, which makes seen emission unit
  gpu::Buffer tree;          // GpuLightNode[]: the light tree (light_tree.h)
};

struct ShadingInputs {
  const SceneBuffers& scene;
  const LightBuffers& lights;
  const ObscuranceFrame& frame;
};

// What every shading kernel of a renderer is specialised for, whatever its variant.
struct ShadingSpecialisation {
  std::uint32_t bands = 1; // one descriptor set per band of the frame
  // Lights chosen by the flat spatial selection alone (kSpecConstantFlatLightSelection): the
  // render samples lights spatially and its frame holds at most kMaxSpatialLights lights.
  bool flatLightSelection = false;
  // The scene's: its compact traversal stack and the texture kinds it has (SceneBuffers::specialisation).
  SceneSpecialisation scene;
};

// The shading specialisation of a render: flat selection where it is the only one its dispatches
// can take (spatial sampling, no more lights than kMaxSpatialLights, spare slots included), and
// the scene's own (the compact stack where its BVH fits it, the texture kinds it uses).
ShadingSpecialisation shadingSpecialisation(std::uint32_t bands, bool spatialSampling, std::uint32_t lightCapacity,
                                            const SceneSpecialisation& scene);

// The kernel description every shading pass shares: scene bindings, then the shading bindings,
// ShadePush, one descriptor set per band.
gpu::KernelDesc shadingKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s);
// The same shader's probing variant (kSpecConstantProbe, lib/probe.glsl): "<name>.probe".
gpu::KernelDesc probingKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s);
// The variant with the secondary reflectors' code (kSpecConstantReflectors): "<name>.reflectors".
gpu::KernelDesc reflectorKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s);
// The obscurance variant without colour bleeding (kSpecConstantGreyObscurance): "<name>.grey".
gpu::KernelDesc greyObscuranceKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s);
// The variant for one light alone (kSpecConstantPerLight): "<name>.perlight".
gpu::KernelDesc perLightKernelDesc(const char* name, std::span<const std::uint32_t> spirv, const ShadingSpecialisation& s);
// The same shader's variant (of the per-light or probing one) that follows the frame's kept rays
// instead of tracing or drawing them (kSpecConstantReplayRays): "<desc.name>.replay".
gpu::KernelDesc replayingKeptRaysKernelDesc(gpu::KernelDesc desc);
// Whether a dispatch with `push` goes to the per-light variant: one light, not probing.
inline bool takesPerLightVariant(const gpu::ShadePush& push) {
  return (push.band.z & gpu::kShadeFlagPerLight) != 0 && (push.band.z & gpu::kShadeFlagProbe) == 0;
}

// Binds descriptor set `band` of a shading kernel.
void bindShadingInputs(gpu::Kernel& kernel, std::uint32_t band, const ShadingInputs& in);

// Push constants of the shading passes for band `band` (the rest of `push` is the caller's).
inline gpu::ShadePush forBand(gpu::ShadePush push, const FrameLayout& layout, std::uint32_t band) {
  push.band = glm::uvec4(layout.bands[band].firstRow, layout.bands[band].rows, push.band.z, push.band.w);
  return push;
}

} // namespace obscura::render
