// one_shot.h — one finished frame from the persistent renderers, with what the tests inspect:
// the image and the figures a render reports.
#pragma once
#include <cstdint>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"

namespace obscura::test {

struct ObscuranceResult {
  io::Image image;                  // every AOV (obscuranceAovNames())
  render::RenderStats stats;
  render::AmbientTerm ambient;
  glm::vec3 ambientIntensity{0.0f};
  render::LightSet lights;
  float dMax = 0.0f;
};

struct PathTraceResult {
  io::Image image;
  render::RenderStats stats;
  std::uint64_t nonFiniteSamples = 0;
};

ObscuranceResult renderObscurances(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                   const render::ObscuranceSettings& settings);
PathTraceResult renderPathTraced(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                 const render::PathTraceSettings& settings);

} // namespace obscura::test
