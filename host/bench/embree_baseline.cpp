#ifdef OBSCURA_HAVE_EMBREE
#include "bench/embree_baseline.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <thread>

#include <embree3/rtcore.h>
#include <fmt/core.h>
#include <pmmintrin.h>
#include <sys/resource.h>
#include <xmmintrin.h>

#include "core/error.h"

namespace obscura::render {
namespace {

using Clock = std::chrono::steady_clock;

double processCpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto ms = [](const timeval& t) { return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_usec) * 1e-3; };
  return ms(u.ru_utime) + ms(u.ru_stime);
}

void check(RTCDevice device, const char* what) {
  RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE) throw DeviceError(fmt::format("Embree: {} failed (error {})", what, static_cast<int>(e)));
}

// Owns the Embree device and scene.
struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

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

// Runs body(first, last) over chunks of the rays on `threads` threads; returns milliseconds.
template <class Body>
double parallelChunks(std::size_t n, unsigned threads, Body body) {
  constexpr std::size_t kChunk = 1024;
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    // Embree's recommendation for speed: flush denormals to zero.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    for (;;) {
      std::size_t first = next.fetch_add(kChunk, std::memory_order_relaxed);
      if (first >= n) break;
      body(first, std::min(n, first + kChunk));
    }
  };
  auto start = Clock::now();
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

template <class Body>
EmbreeSetResult timeSet(std::size_t n, unsigned threads, int repeats, std::size_t hits, Body body) {
  std::vector<double> times;
  EmbreeSetResult r;
  r.bestCpuMs = std::numeric_limits<double>::infinity();
  for (int k = 0; k < repeats; ++k) {
    double c0 = processCpuMs();
    times.push_back(parallelChunks(n, threads, body));
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
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  repeats = std::max(1, repeats);
  EmbreeBaselineResult result;
  result.threads = threads;

  EmbreeScene es;
  const std::string config = fmt::format("threads={}", threads);
  es.device = rtcNewDevice(config.c_str());
  if (!es.device) throw DeviceError("Embree: rtcNewDevice failed");
  es.scene = rtcNewScene(es.device);
  check(es.device, "rtcNewScene");
  RTCGeometry geometry = rtcNewGeometry(es.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  check(es.device, "rtcNewGeometry");
  // Embree reads vertices with 16-byte loads: its shared/new buffers are padded for that.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), scene.positions.size()));
  auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), scene.triangles.size()));
  check(es.device, "rtcSetNewGeometryBuffer");
  for (std::size_t i = 0; i < scene.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) vertices[3 * i + k] = scene.positions[i][k];
  for (std::size_t i = 0; i < scene.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = scene.triangles[i][k];
  auto buildStart = Clock::now();
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(es.scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(es.scene);
  result.buildSeconds = std::chrono::duration<double>(Clock::now() - buildStart).count();
  check(es.device, "rtcCommitScene");

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
      rtcIntersect1(es.scene, &context, &rh);
      hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    if (counting) closestHits.fetch_add(hits, std::memory_order_relaxed);
  };
  parallelChunks(closestRays.size(), threads, closestBody); // warm-up and hit count
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
      rtcOccluded1(es.scene, &context, &ray);
      hits += ray.tfar < 0.0f;
    }
    if (counting) occluded.fetch_add(hits, std::memory_order_relaxed);
  };
  parallelChunks(shadowRays.size(), threads, shadowBody);
  counting = false;
  result.shadow = timeSet(shadowRays.size(), threads, repeats, occluded.load(), shadowBody);
  check(es.device, "tracing");
  return result;
}

} // namespace obscura::render
#endif // OBSCURA_HAVE_EMBREE
