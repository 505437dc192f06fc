// embree_scene.h — an Intel Embree 3 device and scene holding a scene's triangles, and the thread
// pool the baselines trace with (bench-rays' ray sets, the obscurance-only frame).
// Compiled only when CMake finds Embree 3 (OBSCURA_HAVE_EMBREE).
#pragma once
#ifdef OBSCURA_HAVE_EMBREE
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <thread>
#include <vector>

#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include "scene/scene.h"

namespace obscura::bench {

// Owns the device and the committed scene (RTC_BUILD_QUALITY_MEDIUM, Embree's default).
class EmbreeScene {
public:
  // `threads` 0: hardware concurrency. Throws DeviceError on an Embree error.
  EmbreeScene(const scene::Scene& scene, unsigned threads);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene handle() const { return scene_; }
  unsigned threads() const { return threads_; }
  double buildSeconds() const { return buildSeconds_; } // rtcCommitScene
  // DeviceError naming `what` if Embree reported an error.
  void check(const char* what) const;

private:
  unsigned threads_ = 1;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  double buildSeconds_ = 0.0;
};

// Runs body(first, last) over [0, n) in chunks of `chunk` on `threads` std::threads (this one
// included); returns the wall milliseconds.
template <class Body>
double parallelChunks(std::size_t n, unsigned threads, std::size_t chunk, Body body) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    // Embree's recommendation for speed: flush denormals to zero.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    for (;;) {
      std::size_t first = next.fetch_add(chunk, std::memory_order_relaxed);
      if (first >= n) break;
      body(first, std::min(n, first + chunk));
    }
  };
  auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < threads; ++k) pool.emplace_back(worker);
  // This thread's floating-point mode is put back after its share: left flushing denormals, it
  // changed what a later recovery in the same process merged (the classroom's RMSE 0.031 ->
  // 0.038, 172 pixels filled instead of merged: BENCHMARKS "a floating-point mode left behind").
  const unsigned mode = _mm_getcsr();
  worker();
  _mm_setcsr(mode);
  for (auto& t : pool) t.join();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

} // namespace obscura::bench
#endif // OBSCURA_HAVE_EMBREE
