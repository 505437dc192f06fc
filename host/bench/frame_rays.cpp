#include "bench/frame_rays.h"

#include <bit>
#include <cmath>

namespace obscura::bench {
namespace {

constexpr float kPi = 3.14159265358979323846f;

// lib/sampling.glsl systematicGrid: nPhi x nTheta with nTheta the largest divisor <= sqrt(n).
glm::uvec2 systematicGrid(std::uint32_t n) {
  if (n == 0) return glm::uvec2(0);
  std::uint32_t d = static_cast<std::uint32_t>(std::sqrt(static_cast<double>(n)));
  while (d * d > n) --d;
  while ((d + 1) * (d + 1) <= n) ++d;
  while (n % d != 0) --d;
  return {n / d, d};
}

// lib/sampling.glsl sampleCosineHemisphere (Malley's method).
glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
  u = glm::min(u, glm::vec2(0.99999994f));
  const float sinTheta = std::sqrt(u.y), cosTheta = std::sqrt(1.0f - u.y), phi = 2.0f * kPi * u.x;
  return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

// lib/ray.glsl offsetRayOrigin (Wächter & Binder, Ray Tracing Gems ch. 6).
glm::vec3 offsetRayOrigin(glm::vec3 p, glm::vec3 n, float sceneScale) {
  const float threshold = sceneScale / 32.0f, step = sceneScale / 65536.0f;
  glm::vec3 out;
  for (int k = 0; k < 3; ++k) {
    const auto ofi = static_cast<std::int32_t>(256.0f * n[k]);
    const float moved = std::bit_cast<float>(std::bit_cast<std::int32_t>(p[k]) + (p[k] < 0.0f ? -ofi : ofi));
    out[k] = std::abs(p[k]) < threshold ? p[k] + step * n[k] : moved;
  }
  return out;
}

} // namespace

std::uint32_t pcgHash(std::uint32_t v) {
  const std::uint32_t state = v * 747796405u + 2891336453u;
  const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

std::uint32_t rngSeed(glm::uvec2 pixel, std::uint32_t sampleIndex, std::uint32_t seed) {
  return pcgHash(pixel.x ^ pcgHash(pixel.y ^ pcgHash(sampleIndex ^ pcgHash(seed))));
}

float rngNext(std::uint32_t& state) {
  state = state * 747796405u + 2891336453u;
  std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  word = (word >> 22u) ^ word;
  return static_cast<float>(word >> 8u) * (1.0f / 16777216.0f);
}

glm::vec3 cameraRayDirection(const ObscuranceFrameWork& work, glm::uvec2 pixel, std::uint32_t sample) {
  std::uint32_t rng = rngSeed(pixel, 0u, work.seed);
  const float sx = rngNext(rng);
  const float sy = rngNext(rng);
  const glm::vec2 kR2(0.7548776662466927f, 0.5698402909980532f);
  const glm::vec2 position = glm::vec2(pixel) + glm::fract(glm::vec2(sx, sy) + static_cast<float>(sample) * kR2);
  const gpu::GpuCamera& c = work.camera;
  const float tanHalf = c.origin.w, aspect = c.forward.w;
  const float x = (2.0f * position.x / static_cast<float>(work.width) - 1.0f) * tanHalf * aspect;
  const float y = (1.0f - 2.0f * position.y / static_cast<float>(work.height)) * tanHalf;
  return glm::normalize(glm::vec3(c.forward) + x * glm::vec3(c.right) + y * glm::vec3(c.up));
}

ObscuranceRaySet::ObscuranceRaySet(const ObscuranceFrameWork& work, glm::uvec2 pixel, std::uint32_t sample,
                                   glm::vec3 position, glm::vec3 ng, glm::vec3 n)
    : grid_(systematicGrid(work.obscuranceRays)), n_(n) {
  std::uint32_t rng = rngSeed(pixel, sample, work.seed ^ 0x9e3779b9u);
  offset_.x = rngNext(rng);
  offset_.y = rngNext(rng);
  origin_ = offsetRayOrigin(position, ng, work.sceneScale);
  // lib/sampling.glsl orthonormalBasis (Duff et al. 2017).
  const float s = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (s + n.z), c = n.x * n.y * a;
  t_ = {1.0f + s * n.x * n.x * a, s * c, -s * n.x};
  b_ = {c, s + n.y * n.y * a, -n.y};
}

glm::vec3 ObscuranceRaySet::direction(std::uint32_t i) const {
  const glm::vec2 cell(static_cast<float>(i % grid_.x), static_cast<float>(i / grid_.x));
  const glm::vec3 local = sampleCosineHemisphere((cell + offset_) / glm::vec2(grid_));
  return local.x * t_ + local.y * b_ + local.z * n_;
}

} // namespace obscura::bench
