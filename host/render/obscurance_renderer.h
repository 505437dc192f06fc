// obscurance_renderer.h — ray-traced obscurances [RTO] as GPU passes, progressive:
// each iteration adds one primary sample per pixel with its shadow and obscurance rays:
//
//   primary.comp -> G-buffer -> shadow.comp     -> D_s  (one basis buffer per light, unit E_s)
//                            -> obscurance.comp -> A, W
//                            -> specular_queue.comp -> glossy pixels -> specular.comp (indirect
//                               dispatch): specular paths, D_s and A gathered at their vertices
//   after the last iteration: compose.comp  C = sum_s E_s D_s + I_a(E) A + emission [SPEC §3]
//
// A pass the scene does not need is not dispatched (no light with power: no shadow pass).
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "io/image_io.h"
#include "render/scene/ambient.h"
#include "render/aov_render.h"
#include "render/scene/light_set.h"
#include "scene/scene.h"

namespace obscura::render {

enum class RhoKind : std::uint32_t { Sqrt = 0, Exp = 1, Ao = 2 };

struct ObscuranceSettings {
  std::uint32_t width = 512, height = 512;
  std::uint32_t spp = 8;             // primary samples (iterations) per pixel
  std::uint32_t seed = 1;
  scene::Camera camera;
  std::uint32_t shadowRays = 5;      // N_s per hit
  std::uint32_t obscuranceRays = 5;  // N_obs per hit
  RhoKind rho = RhoKind::Sqrt;
  float tau = 3.0f;                  // for RhoKind::Exp
  float dMax = 0.0f;                 // 0 = a quarter of the largest bounding-box extent [SPEC §1.3]
  bool systematic = true;            // [RTO §4.2]
  bool colourBleeding = true;        // W_c [RTO eq. 6]; false: grey W [RTO eq. 2]
  std::uint32_t maxDepth = 6;        // specular paths: scattering vertices, the primary hit is 1
};

// dMax used when the settings leave it 0: a quarter of the scene's largest extent.
float defaultDMax(const scene::Bounds& bounds);

// The AOVs of an obscurance render, in EXR layer order [RTO fig. 5].
const std::vector<std::string>& obscuranceAovNames();

struct ObscuranceResult {
  io::Image image;            // every AOV (obscuranceAovNames() + the primary AOVs)
  RenderStats stats;          // per-pass GPU ms and rays
  AmbientTerm ambient;        // R_ave, I_a weights per light
  glm::vec3 ambientIntensity; // I_a(E) with the scene's emissions
  LightSet lights;
  float dMax = 0.0f;
};

ObscuranceResult renderObscurances(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                   const ObscuranceSettings& settings, const ProgressFn& progress = nullptr);

// The largest single frame buffer (it must fit the device's maxStorageBufferRange).
std::uint64_t obscuranceLargestBuffer(std::uint32_t width, std::uint32_t height, std::size_t lights);

// Device memory the frame buffers need (beyond the scene) for `lights` lights.
std::uint64_t obscuranceBytesNeeded(std::uint32_t width, std::uint32_t height, std::size_t lights);

} // namespace obscura::render
