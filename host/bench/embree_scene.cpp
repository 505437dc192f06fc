#ifdef OBSCURA_HAVE_EMBREE
#include "bench/embree_scene.h"

#include <fmt/core.h>

#include "core/error.h"

namespace obscura::bench {

EmbreeScene::EmbreeScene(const scene::Scene& scene, unsigned threads)
    : threads_(threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : threads) {
  const std::string config = fmt::format("threads={}", threads_);
  device_ = rtcNewDevice(config.c_str());
  if (!device_) throw DeviceError("Embree: rtcNewDevice failed");
  scene_ = rtcNewScene(device_);
  check("rtcNewScene");
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  check("rtcNewGeometry");
  // Embree reads vertices with 16-byte loads: its shared/new buffers are padded for that.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), scene.positions.size()));
  auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), scene.triangles.size()));
  check("rtcSetNewGeometryBuffer");
  for (std::size_t i = 0; i < scene.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) vertices[3 * i + k] = scene.positions[i][k];
  for (std::size_t i = 0; i < scene.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = scene.triangles[i][k];
  auto buildStart = std::chrono::steady_clock::now();
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene_);
  buildSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - buildStart).count();
  check("rtcCommitScene");
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::check(const char* what) const {
  RTCError e = rtcGetDeviceError(device_);
  if (e != RTC_ERROR_NONE) throw DeviceError(fmt::format("Embree: {} failed (error {})", what, static_cast<int>(e)));
}

} // namespace obscura::bench
#endif // OBSCURA_HAVE_EMBREE
