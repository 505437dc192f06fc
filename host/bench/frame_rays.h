// frame_rays.h — the rays of an obscurance-only frame made on the CPU the way the GPU passes make
// them, so that a baseline ray tracer (Embree, `bench-rays --frame`) traces the same work:
//   camera rays   primary.comp: the pixel's shift from rngSeed(p, 0, seed), sub-pixel position
//                 R2 point `sample` (lib/rng.glsl, lib/camera.glsl), the same directions up to
//                 float rounding;
//   obscurance    obscurance.comp: N_obs rays per hit from rngSeed(p, sample, seed ^ 0x9e3779b9),
//                 systematic [RTO §4.2] cosine-distributed around the normal (lib/sampling.glsl),
//                 tmax = dMax, from an origin offset off the surface (lib/ray.glsl).
// These are twins of the shader code, not shared with it: should the shaders' sampling change, the
// baseline's rays would differ only statistically, which is all the comparison needs.
#pragma once
#include <cstdint>

#include <glm/glm.hpp>

#include "shared/host_device.h"

namespace obscura::bench {

// What the obscurance-only frame asks for (the issue's: 8 spp x 5 rays, dMax 2).
struct ObscuranceFrameWork {
  std::uint32_t width = 400, height = 300;
  std::uint32_t spp = 8;
  std::uint32_t obscuranceRays = 5;
  float dMax = 2.0f;
  std::uint32_t seed = 1;
  gpu::GpuCamera camera{};
  float sceneScale = 1.0f; // render::sceneScale of the scene's bounds (the origin offset's scale)
};

// PCG hash and stream of lib/rng.glsl.
std::uint32_t pcgHash(std::uint32_t v);
std::uint32_t rngSeed(glm::uvec2 pixel, std::uint32_t sampleIndex, std::uint32_t seed);
float rngNext(std::uint32_t& state);

// The unit direction of pixel `pixel`'s camera ray of sample `sample` (primary.comp).
glm::vec3 cameraRayDirection(const ObscuranceFrameWork& work, glm::uvec2 pixel, std::uint32_t sample);

// The obscurance rays of one hit: origin off the surface at `position` along the geometric normal
// `ng` (facing the ray's side), directions systematic around `n` (the shading normal; the GPU
// traces only those above `ng`).
class ObscuranceRaySet {
public:
  ObscuranceRaySet(const ObscuranceFrameWork& work, glm::uvec2 pixel, std::uint32_t sample, glm::vec3 position,
                   glm::vec3 ng, glm::vec3 n);
  glm::vec3 origin() const { return origin_; }
  // Ray i < work.obscuranceRays.
  glm::vec3 direction(std::uint32_t i) const;

private:
  glm::uvec2 grid_;
  glm::vec2 offset_;
  glm::vec3 origin_, t_, b_, n_;
};

} // namespace obscura::bench
