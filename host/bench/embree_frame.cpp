#ifdef OBSCURA_HAVE_EMBREE
#include "bench/embree_frame.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bench/cpu_time.h"
#include "bench/embree_scene.h"

namespace obscura::bench {
namespace {

// Closest hit of one ray; t = +inf on a miss.
struct EmbreeHit {
  float t = std::numeric_limits<float>::infinity();
  glm::vec3 ng{0.0f};
};

EmbreeHit intersect(RTCScene scene, glm::vec3 origin, glm::vec3 direction, float tmax) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = origin.x;
  rh.ray.org_y = origin.y;
  rh.ray.org_z = origin.z;
  rh.ray.tnear = 0.0f;
  rh.ray.dir_x = direction.x;
  rh.ray.dir_y = direction.y;
  rh.ray.dir_z = direction.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = tmax;
  rh.ray.mask = ~0u;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context, &rh);
  EmbreeHit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.t = rh.ray.tfar;
  hit.ng = glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  return hit;
}

struct RowCounts {
  std::uint64_t primaryHits = 0, obscuranceRays = 0, traced = 0;
};

// Row y of the frame, every sample: W summed over samples / spp into out[x].
RowCounts traceRow(RTCScene scene, const ObscuranceFrameWork& work, std::uint32_t y, float* out) {
  RowCounts counts;
  const glm::vec3 eye(work.camera.origin);
  const float invN = 1.0f / static_cast<float>(std::max(work.obscuranceRays, 1u));
  for (std::uint32_t x = 0; x < work.width; ++x) {
    float sum = 0.0f;
    for (std::uint32_t s = 0; s < work.spp; ++s) {
      const glm::vec3 direction = cameraRayDirection(work, {x, y}, s);
      const EmbreeHit hit = intersect(scene, eye, direction, std::numeric_limits<float>::infinity());
      if (!std::isfinite(hit.t)) continue;
      ++counts.primaryHits;
      counts.obscuranceRays += work.obscuranceRays;
      // The normal facing the camera; Embree gives no shading normal, so the rays are
      // cosine-distributed around the geometric one (the GPU's: around the shading normal).
      glm::vec3 n = glm::normalize(hit.ng);
      if (glm::dot(n, direction) > 0.0f) n = -n;
      const ObscuranceRaySet rays(work, {x, y}, s, eye + hit.t * direction, n, n);
      float w = 0.0f;
      for (std::uint32_t i = 0; i < work.obscuranceRays; ++i) {
        const glm::vec3 d = rays.direction(i);
        if (glm::dot(d, n) <= 0.0f) continue; // blocked at d = 0: rho(0) = 0
        ++counts.traced;
        const EmbreeHit o = intersect(scene, rays.origin(), d, work.dMax);
        w += std::isfinite(o.t) ? std::sqrt(std::clamp(o.t / work.dMax, 0.0f, 1.0f)) : 1.0f;
      }
      sum += w * invN;
    }
    out[x] = sum / static_cast<float>(std::max(work.spp, 1u));
  }
  return counts;
}

} // namespace

EmbreeFrameResult runEmbreeFrame(const scene::Scene& scene, const ObscuranceFrameWork& work, int repeats,
                                 unsigned threads) {
  EmbreeScene es(scene, threads);
  EmbreeFrameResult result;
  result.threads = es.threads();
  result.obscurance.assign(std::size_t(work.width) * work.height, 0.0f);
  std::vector<RowCounts> rows(work.height);
  auto body = [&](std::size_t first, std::size_t last) {
    for (std::size_t y = first; y < last; ++y)
      rows[y] = traceRow(es.handle(), work, static_cast<std::uint32_t>(y), &result.obscurance[y * work.width]);
  };
  parallelChunks(work.height, result.threads, 1, body); // warm-up (caches, page faults)
  std::vector<double> times;
  result.bestCpuMs = std::numeric_limits<double>::infinity();
  for (int k = 0; k < std::max(1, repeats); ++k) {
    const double c0 = processCpuMs();
    times.push_back(parallelChunks(work.height, result.threads, 1, body));
    result.bestCpuMs = std::min(result.bestCpuMs, processCpuMs() - c0);
  }
  es.check("tracing the frame");
  std::sort(times.begin(), times.end());
  result.bestMs = times.front();
  result.medianMs = times[times.size() / 2];
  result.primaryRays = std::uint64_t(work.width) * work.height * work.spp;
  for (const RowCounts& r : rows) {
    result.primaryHits += r.primaryHits;
    result.obscuranceRays += r.obscuranceRays;
    result.obscuranceRaysTraced += r.traced;
  }
  return result;
}

} // namespace obscura::bench
#endif // OBSCURA_HAVE_EMBREE
