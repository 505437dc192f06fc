#ifdef OBSCURA_HAVE_EMBREE
#include "bench/embree_baseline.h"

#include <algorithm>
#include <atomic>
#include <limits>

#include "bench/cpu_time.h"
#include "bench/embree_scene.h"

namespace obscura::bench {
namespace {

RTCRay toRtcRay(const gpu::GpuRay& r) {
  RTCRay ray;
  ray.org_x = r.origin.x;
  ray.org_y = r.origin.y;
  ray.org_z = r.origin.z;
  ray.tnear = r.origin.w;
  ray.dir_x = r.direction.x;
  ray.dir_y = r.direction.y;
  ray.dir_z = r.direction.z;
  ray.time = 0.0f;
  ray.tfar = r.direction.w;
  ray.mask = ~0u;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

constexpr std::size_t kChunk = 1024; // rays a thread takes at a time

template <class Body>
EmbreeSetResult timeSet(std::size_t n, unsigned threads, int repeats, std::size_t hits, Body body) {
  std::vector<double> times;
  EmbreeSetResult r;
  r.bestCpuMs = std::numeric_limits<double>::infinity();
  for (int k = 0; k < repeats; ++k) {
    double c0 = processCpuMs();
    times.push_back(parallelChunks(n, threads, kChunk, body));
    r.bestCpuMs = std::min(r.bestCpuMs, processCpuMs() - c0);
  }
  std::sort(times.begin(), times.end());
  r.bestMs = times.front();
  r.medianMs = times[times.size() / 2];
  r.hitFraction = n ? static_cast<double>(hits) / static_cast<double>(n) : 0.0;
  return r;
}

} // namespace

EmbreeBaselineResult runEmbreeBaseline(const scene::Scene& scene, const std::vector<gpu::GpuRay>& closestRays,
                                       const std::vector<gpu::GpuRay>& shadowRays, int repeats, unsigned threads) {
  repeats = std::max(1, repeats);
  EmbreeScene es(scene, threads);
  threads = es.threads();
  EmbreeBaselineResult result;
  result.threads = threads;
  result.buildSeconds = es.buildSeconds();

  // Closest hit: rtcIntersect1, the fastest Embree path for incoherent single rays.
  std::atomic<std::size_t> closestHits{0};
  bool counting = true;
  auto closestBody = [&](std::size_t first, std::size_t last) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    std::size_t hits = 0;
    for (std::size_t i = first; i < last; ++i) {
      RTCRayHit rh;
      rh.ray = toRtcRay(closestRays[i]);
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(es.handle(), &context, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    if (counting) closestHits.fetch_add(hits, std::memory_order_relaxed);
  };
  parallelChunks(closestRays.size(), threads, kChunk, closestBody); // warm-up and hit count
  counting = false;
  result.closest = timeSet(closestRays.size(), threads, repeats, closestHits.load(), closestBody);

  // Shadow: rtcOccluded1 (sets tfar to -inf when occluded).
  std::atomic<std::size_t> occluded{0};
  counting = true;
  auto shadowBody = [&](std::size_t first, std::size_t last) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    std::size_t hits = 0;
    for (std::size_t i = first; i < last; ++i) {
      RTCRay ray = toRtcRay(shadowRays[i]);
      rtcOccluded1(es.handle(), &context, &ray);
      hits += ray.tfar < 0.0f;
    }
    if (counting) occluded.fetch_add(hits, std::memory_order_relaxed);
  };
  parallelChunks(shadowRays.size(), threads, kChunk, shadowBody);
  counting = false;
  result.shadow = timeSet(shadowRays.size(), threads, repeats, occluded.load(), shadowBody);
  es.check("tracing");
  return result;
}

} // namespace obscura::bench
#endif // OBSCURA_HAVE_EMBREE
