// The recovery's gather (recover/photo_gather.h) traced on the device equals its CPU twin: the same
// rays through the renderer's traversal and through the host's BVH give the same indirect light.
#include <cmath>

#include <gtest/gtest.h>

#include "recover/photo_gather.h"
#include "recover/recovery_scene.h"
#include "recover_cornell_fixture.h"
#include "render/scene_data/ray_batch.h"

namespace obscura::test {
namespace {

// What the camera sees through each pixel's centre, by the CPU's traversal (the pinhole that
// projectToPixel inverts).
recover::PixelGeometry pixelGeometry(const scene::Scene& room, const bvh::Bvh& bvh, const scene::Camera& camera,
                                     int width, int height) {
  const std::vector<std::uint32_t> objectOf = recover::triangleObjects(room);
  const glm::vec3 forward = glm::normalize(camera.forward);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tanHalf = std::tan(0.5f * camera.yfov), aspect = float(width) / float(height);
  recover::PixelGeometry g{.width = width, .height = height};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float sx = (2.0f * (float(x) + 0.5f) / float(width) - 1.0f) * tanHalf * aspect;
      const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(height)) * tanHalf;
      const glm::vec3 dir = forward + sx * right + sy * up;
      const bvh::Hit hit = bvh::closestHit(bvh, bvh::Ray{camera.position, dir});
      if (!hit.hit()) {
        g.position.emplace_back(0.0f);
        g.normal.emplace_back(0.0f, 0.0f, 1.0f);
        g.object.push_back(-1);
        continue;
      }
      const glm::uvec3 t = room.triangles[hit.primitive];
      const glm::vec3 a = room.positions[t.x], b = room.positions[t.y], c = room.positions[t.z];
      glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
      if (glm::dot(n, dir) > 0.0f) n = -n; // facing the camera
      g.position.push_back(a + hit.u * (b - a) + hit.v * (c - a));
      g.normal.push_back(n);
      g.object.push_back(static_cast<std::int32_t>(objectOf[hit.primitive]));
    }
  return g;
}

TEST_F(RecoverCornell, GatherOnTheDeviceEqualsItsCpuTwin) {
  const recover::PixelGeometry pixels = pixelGeometry(room_->scene, room_->bvh, camera(), photos_->width, photos_->height);
  constexpr std::uint32_t kRays = 8; // 0.5 million gather rays, and the shadow rays of their hidden hits
  render::CpuRayBatch cpuRays(room_->bvh);
  const recover::PhotoGather onCpu(room_->scene, cpuRays, camera(), pixels, photos_->shots, kRays, 1, 0);
  const recover::PhotoGather onDevice =
      recover::PhotoGather::onDevice(context(), room_->scene, room_->bvh, camera(), pixels, photos_->shots, kRays, 1, 0);
  EXPECT_EQ(onDevice.rays(), onCpu.rays());
  EXPECT_GT(onCpu.hiddenFraction(), 0.05); // the shadow rays are exercised too
  EXPECT_NEAR(onDevice.seenFraction(), onCpu.seenFraction(), 1e-4);
  EXPECT_NEAR(onDevice.hiddenFraction(), onCpu.hiddenFraction(), 1e-4);
  const std::vector<glm::vec3> grey(room_->scene.objects.size(), glm::vec3(0.5f));
  const std::vector<recover::PhotoGather::Cut> ambient(
      photos_->shots.size(), recover::PhotoGather::uniformCut(room_->scene.objects.size(), glm::vec3(0.05f)));
  const auto a = onCpu.indirect(photos_->shots, grey, ambient), b = onDevice.indirect(photos_->shots, grey, ambient);
  // A ray through an edge or a vertex may find the neighbouring triangle on one side: a few pixels
  // differ by one ray's share, the images' means by far less.
  for (std::size_t shot = 0; shot < a.size(); ++shot) {
    double sumA = 0.0, sumB = 0.0;
    std::size_t differing = 0;
    for (std::size_t p = 0; p < a[shot].size(); ++p) {
      sumA += a[shot][p].x + a[shot][p].y + a[shot][p].z;
      sumB += b[shot][p].x + b[shot][p].y + b[shot][p].z;
      if (glm::any(glm::greaterThan(glm::abs(a[shot][p] - b[shot][p]), glm::vec3(1e-5f + 1e-4f * glm::length(a[shot][p])))))
        ++differing;
    }
    EXPECT_NEAR(sumB / sumA, 1.0, 1e-4) << "shot " << shot;
    EXPECT_LT(differing, a[shot].size() / 1000) << "shot " << shot << ": pixels differing";
  }
}

} // namespace
} // namespace obscura::test
