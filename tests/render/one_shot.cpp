#include "render/one_shot.h"

namespace obscura::test {

ObscuranceResult renderObscurances(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                   const render::ObscuranceSettings& settings) {
  render::ObscuranceRenderer renderer(context, scene, bvh, settings);
  renderer.render();
  return {.image = renderer.image(), .stats = renderer.stats(), .ambient = renderer.ambient(),
          .ambientIntensity = renderer.ambientIntensity(), .lights = renderer.lights(), .dMax = renderer.dMax()};
}

PathTraceResult renderPathTraced(const gpu::Context& context, const scene::Scene& scene, const bvh::Bvh& bvh,
                                 const render::PathTraceSettings& settings) {
  render::PathTracer tracer(context, scene, bvh, settings);
  tracer.render();
  return {.image = tracer.image(), .stats = tracer.stats(), .nonFiniteSamples = tracer.nonFiniteSamples()};
}

} // namespace obscura::test
