// shading_inputs.h — what the shading passes (shadow, obscurance, specular) bind: the scene,
// the lights, and one band of the frame (shaders/lib/shading_bindings.glsl, bindings 0..17); and
// what one of their dispatches does (ShadeSample, ShadeDispatch), packed into ShadePush in one
// place (packShadePush).
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
// Binds descriptor set `band` of a shading kernel.
void bindShadingInputs(gpu::Kernel& kernel, std::uint32_t band, const ShadingInputs& in);

// What every shading dispatch of one sample shares: the render's settings and the sample.
struct ShadeSample {
  std::uint32_t width = 0, height = 0; // of the whole frame
  std::uint32_t sample = 0;            // its index in the frame's sequence (seeds)
  std::uint32_t seed = 1;
  std::uint32_t lights = 0;
  std::uint32_t shadowRays = 0;        // N_s per hit
  std::uint32_t obscuranceRays = 0;    // N_obs per hit
  float dMax = 0.0f;
  float tau = 3.0f;                    // for kRhoExp
  std::uint32_t rho = gpu::kRhoSqrt;   // kRho*
  std::uint32_t maxDepth = 1;          // a specular path's scattering vertices, the primary hit is 1
  bool systematic = true;              // obscurance rays by systematic sampling [RTO §4.2]
  bool colourBleeding = true;          // W_c [RTO eq. 6]
  bool areaLightSampling = false;      // the paper's light sampling (kFlagAreaLightSampling)
  bool glossyMis = false;              // kFlagGlossyMis
  bool secondaryReflectors = false;    // kFlagSecondaryReflectors (with kappa and r below)
  bool vertexRaysByThroughput = true;  // kFlagVertexRaysByThroughput
  bool darkEscapes = false;            // kFlagDarkEscapes
  glm::vec3 averageReflectance{0.0f};  // R_ave (SPEC §1.2)
  glm::vec3 eye{0.0f};                 // the camera's position
  float sceneSize = 1.0f;              // scales the ray-origin offset (ray.glsl)
  glm::vec3 kappa{1.0f};               // the share of I_a beyond the first bounce
  float unmarkedFirstBounce = 1.0f;    // r (secondary_reflectors.h)
};

// What one dispatch of a shading pass does. The kernel a pass takes follows from it (probing,
// per-light, replaying variants) and packShadePush writes it into the push constants.
struct ShadeDispatch {
  // One light alone (the relighting paper's per-light sampling, an added light's rays; the
  // per-light variant unless probing); kInvalidIndex: every light.
  std::uint32_t light = gpu::kInvalidIndex;
  // A geometry edit's dirty test: the rays of the listed candidates tested against the changed
  // boxes instead of shading (the probing variant, lib/probe.glsl).
  bool probe = false;
  // Only the pixels of the frame's dirty list (a geometry edit's retrace and probes), dispatched
  // indirectly.
  bool dirtyOnly = false;
  // The frame keeps this sample's rays: a plain dispatch writes them, a probe or one light's
  // dispatch follows them (the replaying variants, lib/kept_rays.glsl).
  bool keptRays = false;
  // specular.comp: the ambient alone along the paths (per-light sampling then follows them light
  // by light).
  bool noDirect = false;

  bool oneLight() const { return light != gpu::kInvalidIndex; }
  // Whether the per-light variant takes it: one light, not probing.
  bool perLightVariant() const { return oneLight() && !probe; }
};

// The push constants of a shading dispatch over band `band`, at specular path depth `pathDepth`
// (specular.comp; 0 elsewhere): the one place ShadePush is filled.
gpu::ShadePush packShadePush(const ShadeSample& sample, const ShadeDispatch& dispatch, const FrameLayout& layout,
                             std::uint32_t band, std::uint32_t pathDepth = 0);

} // namespace obscura::render
