// photo_gather.cpp — see photo_gather.h.
#include "recover/photo_gather.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

#include "recover/recovery_scene.h"
#include "render/gpu_ray_batch.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::recover {
namespace {

// A 32-bit integer hash (PCG's output permutation), for per-pixel sample shifts.
std::uint32_t hash(std::uint32_t v) {
  const std::uint32_t state = v * 747796405u + 2891336453u;
  const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}
float unit(std::uint32_t v) { return float(v >> 8) * (1.0f / 16777216.0f); }
// Van der Corput: the bits of k mirrored about the binary point.
float radicalInverse2(std::uint32_t k) {
  k = (k << 16u) | (k >> 16u);
  k = ((k & 0x00ff00ffu) << 8u) | ((k & 0xff00ff00u) >> 8u);
  k = ((k & 0x0f0f0f0fu) << 4u) | ((k & 0xf0f0f0f0u) >> 4u);
  k = ((k & 0x33333333u) << 2u) | ((k & 0xccccccccu) >> 2u);
  k = ((k & 0x55555555u) << 1u) | ((k & 0xaaaaaaaau) >> 1u);
  return unit(k);
}

// Two unit vectors completing n to an orthonormal frame (Duff et al. 2017).
void frame(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z), c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

} // namespace

std::int64_t projectToPixel(const scene::Camera& camera, int width, int height, const glm::vec3& point) {
  const glm::vec3 forward = glm::normalize(camera.forward);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const glm::vec3 d = point - camera.position;
  const float z = glm::dot(d, forward);
  if (z <= 0.0f) return -1;
  const float tanHalf = std::tan(0.5f * camera.yfov), aspect = float(width) / float(height);
  const float sx = glm::dot(d, right) / z, sy = glm::dot(d, up) / z;
  const float px = 0.5f * (sx / (tanHalf * aspect) + 1.0f) * float(width);
  const float py = 0.5f * (1.0f - sy / tanHalf) * float(height);
  if (!(px >= 0.0f && px < float(width) && py >= 0.0f && py < float(height))) return -1;
  return std::int64_t(py) * width + std::int64_t(px);
}

PhotoGather::PhotoGather(const scene::Scene& room, render::RayBatch& rays, const scene::Camera& camera,
                         const PixelGeometry& pixels, const std::vector<Shot>& shots, std::uint32_t raysPerPixel,
                         std::uint32_t seed, int smoothRadius)
    : geometry_(&pixels), smoothRadius_(smoothRadius), pixels_(pixels.position.size()), shots_(shots.size()), raysPerPixel_(raysPerPixel) {
  const std::vector<std::uint32_t> objectOf = triangleObjects(room);
  const float scale = render::sceneScale(room.bounds);
  const float offset = 1e-4f * scale;       // ray origins off the surface
  const float samePlane = 2e-3f * scale;    // a seen pixel's point within this of the hit's plane
  seenStart_.reserve(pixels_ + 1);
  hiddenStart_.reserve(pixels_ + 1);
  // The pixels a chunk at a time, each chunk's rays traced together (one dispatch on a device):
  // its gather rays, then the shadow rays from its hidden hits to every shot's lamp.
  const std::size_t pixelsPerChunk = std::max<std::size_t>(1, kRaysPerBatch / std::max(raysPerPixel, 1u));
  std::vector<bvh::Ray> gatherRays, shadowRays;
  struct PendingDirect {
    std::size_t at;  // in hiddenDirect_
    float unblocked; // the lamp's light there if nothing is in the way
  };
  std::vector<PendingDirect> pending;
  for (std::size_t first = 0; first < pixels_; first += pixelsPerChunk) {
    const std::size_t last = std::min(pixels_, first + pixelsPerChunk);
    gatherRays.clear();
    for (std::size_t p = first; p < last; ++p) {
      if (pixels.object[p] < 0) continue;
      const glm::vec3 n = pixels.normal[p];
      const glm::vec3 origin = pixels.position[p] + offset * n;
      glm::vec3 t, b;
      frame(n, t, b);
      // Stratified in the first dimension, van der Corput in the second, shifted per pixel.
      const std::uint32_t h = hash(static_cast<std::uint32_t>(p) ^ hash(seed));
      const float shift1 = unit(h), shift2 = unit(hash(h));
      for (std::uint32_t k = 0; k < raysPerPixel; ++k) {
        const float u1 = std::fmod((float(k) + 0.5f) / float(raysPerPixel) + shift1, 1.0f);
        const float u2 = std::fmod(radicalInverse2(k) + shift2, 1.0f);
        const float r = std::sqrt(u1), phi = 2.0f * glm::pi<float>() * u2;
        gatherRays.push_back(
            {origin, r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - u1)) * n});
      }
    }
    const std::vector<bvh::Hit> hits = rays.closest(gatherRays);
    shadowRays.clear();
    pending.clear();
    std::size_t ray = 0;
    for (std::size_t p = first; p < last; ++p) {
      seenStart_.push_back(static_cast<std::uint32_t>(seen_.size()));
      hiddenStart_.push_back(static_cast<std::uint32_t>(hiddenObject_.size()));
      if (pixels.object[p] < 0) continue;
      rays_ += raysPerPixel;
      for (std::uint32_t k = 0; k < raysPerPixel; ++k, ++ray) {
        const bvh::Hit& hit = hits[ray];
        if (!hit.hit()) continue; // leaves the scene: black
        const glm::vec3 dir = gatherRays[ray].direction;
        const glm::uvec3 tri = room.triangles[hit.primitive];
        const glm::vec3 a = room.positions[tri.x];
        const glm::vec3 q = a + hit.u * (room.positions[tri.y] - a) + hit.v * (room.positions[tri.z] - a);
        glm::vec3 nq = glm::normalize(glm::cross(room.positions[tri.y] - a, room.positions[tri.z] - a));
        if (glm::dot(nq, dir) > 0.0f) nq = -nq; // the side facing P reflects towards it
        const auto object = static_cast<std::int32_t>(objectOf[hit.primitive]);
        const std::int64_t v = projectToPixel(camera, pixels.width, pixels.height, q);
        if (v >= 0) {
          const auto vi = static_cast<std::size_t>(v);
          // The camera sees Q's side if that pixel shows the same object on the same plane, from
          // the same side (its normal faces the camera, so it must agree with nq).
          if (pixels.object[vi] == object && std::abs(glm::dot(pixels.position[vi] - q, nq)) < samePlane &&
              glm::dot(pixels.normal[vi], nq) > 0.9f) {
            seen_.push_back(static_cast<std::uint32_t>(vi));
            continue;
          }
        }
        hiddenObject_.push_back(static_cast<std::uint32_t>(object));
        const glm::vec3 lit = q + offset * nq;
        for (const Shot& shot : shots) {
          const glm::vec3 toLamp = shot.position - lit;
          const float d2 = glm::dot(toLamp, toLamp);
          const float cosine = glm::dot(nq, toLamp) / std::sqrt(d2);
          if (cosine > 0.0f) {
            pending.push_back({hiddenDirect_.size(), shot.intensity * cosine / (glm::pi<float>() * d2)});
            shadowRays.push_back({lit, toLamp, 0.0f, 1.0f - 1e-4f});
          }
          hiddenDirect_.push_back(0.0f);
        }
      }
    }
    const std::vector<float> blocked = rays.blockedAt(shadowRays);
    for (std::size_t i = 0; i < pending.size(); ++i)
      if (std::isinf(blocked[i])) hiddenDirect_[pending[i].at] = pending[i].unblocked;
  }
  seenStart_.push_back(static_cast<std::uint32_t>(seen_.size()));
  hiddenStart_.push_back(static_cast<std::uint32_t>(hiddenObject_.size()));
}

PhotoGather PhotoGather::onDevice(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                                  const scene::Camera& camera, const PixelGeometry& pixels,
                                  const std::vector<Shot>& shots, std::uint32_t raysPerPixel, std::uint32_t seed,
                                  int smoothRadius) {
  const render::SceneBuffers buffers(context, room, bvh);
  render::GpuRayBatch rays(context, buffers, render::TraceShape::forDevice(context, buffers.traversal()));
  return PhotoGather(room, rays, camera, pixels, shots, raysPerPixel, seed, smoothRadius);
}

std::vector<std::vector<glm::vec3>> PhotoGather::indirect(const std::vector<Shot>& shots,
                                                          const std::vector<glm::vec3>& objectReflectance,
                                                          const std::vector<glm::vec3>& hiddenAmbient) const {
  std::vector<std::vector<glm::vec3>> out;
  for (std::size_t i = 0; i < shots_; ++i) {
    std::vector<glm::vec3> lampColour(shots_, glm::vec3(0.0f));
    lampColour[i] = shots[i].color;
    out.push_back(gather(shots[i].radiance, lampColour, objectReflectance, hiddenAmbient[i]));
  }
  return out;
}

std::vector<glm::vec3> PhotoGather::gather(const std::vector<glm::vec3>& radiance,
                                           const std::vector<glm::vec3>& lampColour,
                                           const std::vector<glm::vec3>& objectReflectance,
                                           const glm::vec3& hiddenAmbient) const {
  std::vector<glm::vec3> out(pixels_, glm::vec3(0.0f));
  const float perRay = 1.0f / float(raysPerPixel_);
  for (std::size_t p = 0; p < pixels_; ++p) {
    glm::vec3 sum(0.0f);
    for (std::uint32_t k = seenStart_[p]; k < seenStart_[p + 1]; ++k) sum += radiance[seen_[k]];
    for (std::uint32_t k = hiddenStart_[p]; k < hiddenStart_[p + 1]; ++k) {
      glm::vec3 light = hiddenAmbient;
      for (std::size_t i = 0; i < shots_; ++i) light += hiddenDirect_[std::size_t(k) * shots_ + i] * lampColour[i];
      sum += objectReflectance[hiddenObject_[k]] * light;
    }
    out[p] = sum * perRay;
  }
  if (smoothRadius_ > 0) out = smoothOnSurfaces(out, *geometry_, smoothRadius_);
  return out;
}

std::vector<glm::vec3> smoothOnSurfaces(const std::vector<glm::vec3>& image, const PixelGeometry& pixels, int radius) {
  std::vector<glm::vec3> out = image;
  for (int y = 0; y < pixels.height; ++y)
    for (int x = 0; x < pixels.width; ++x) {
      const std::size_t p = std::size_t(y) * pixels.width + x;
      if (pixels.object[p] < 0) continue;
      glm::vec3 sum(0.0f);
      int n = 0;
      for (int wy = std::max(0, y - radius); wy <= std::min(pixels.height - 1, y + radius); ++wy)
        for (int wx = std::max(0, x - radius); wx <= std::min(pixels.width - 1, x + radius); ++wx) {
          const std::size_t q = std::size_t(wy) * pixels.width + wx;
          if (pixels.object[q] != pixels.object[p] || glm::dot(pixels.normal[q], pixels.normal[p]) < 0.95f) continue;
          sum += image[q];
          ++n;
        }
      out[p] = sum / float(n);
    }
  return out;
}

} // namespace obscura::recover
