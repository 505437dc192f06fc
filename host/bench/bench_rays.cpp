#include "bench/bench_rays.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>

#include <fmt/core.h>

#include "core/error.h"

namespace obscura::bench {
namespace {

struct UniformFloats {
  std::mt19937_64 engine;
  explicit UniformFloats(std::uint64_t seed) : engine(seed) {}
  // 24 random bits -> [0, 1), the same on every platform (std::uniform_real_distribution is not).
  float next() { return static_cast<float>(engine() >> 40) * (1.0f / 16777216.0f); }
  glm::vec3 inBox(const scene::Bounds& b) {
    float x = next(), y = next(), z = next();
    return b.lo + glm::vec3(x, y, z) * (b.hi - b.lo);
  }
};

} // namespace

std::vector<gpu::GpuRay> closestBenchRays(const scene::Bounds& bounds, std::size_t count, std::uint64_t seed) {
  UniformFloats rng(seed);
  std::vector<gpu::GpuRay> rays(count);
  for (auto& ray : rays) {
    glm::vec3 o = rng.inBox(bounds);
    float z = 1.0f - 2.0f * rng.next();
    float phi = 2.0f * std::numbers::pi_v<float> * rng.next();
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    ray.origin = glm::vec4(o, 0.0f);
    ray.direction = glm::vec4(r * std::cos(phi), r * std::sin(phi), z, std::numeric_limits<float>::infinity());
  }
  return rays;
}

std::vector<gpu::GpuRay> shadowBenchRays(const scene::Bounds& bounds, std::size_t count, std::uint64_t seed) {
  UniformFloats rng(seed);
  std::vector<gpu::GpuRay> rays(count);
  for (auto& ray : rays) {
    glm::vec3 p = rng.inBox(bounds);
    glm::vec3 q = rng.inBox(bounds);
    glm::vec3 d = q - p;
    float len = glm::length(d);
    if (len == 0.0f) { d = glm::vec3(0, 0, 1); len = 0.0f; } else { d /= len; }
    ray.origin = glm::vec4(p, 0.0f);
    ray.direction = glm::vec4(d, len);
  }
  return rays;
}

void saveRays(const std::string& path, const std::vector<gpu::GpuRay>& rays) {
  std::string temp = path + ".tmp";
  {
    std::ofstream out(temp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(rays.data()), static_cast<std::streamsize>(rays.size() * sizeof(gpu::GpuRay)));
    if (!out) {
      std::remove(temp.c_str());
      throw InputError(fmt::format("{}: cannot write rays", path));
    }
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    throw InputError(fmt::format("{}: cannot write rays", path));
  }
}

} // namespace obscura::bench
