#include "bench/lane_order.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace obscura::bench {
namespace {

constexpr std::size_t kLanes = 8;

// A list of rays in trace order; `real[i]` false for the lanes that have no ray (a pixel whose
// camera ray missed: its obscurance lanes idle), traced as empty rays (tmax 0).
struct OrderedRays {
  std::vector<gpu::GpuRay> rays;
  std::vector<bool> real;
};

gpu::GpuRay makeRay(glm::vec3 origin, glm::vec3 direction, float tmax) {
  return {glm::vec4(origin, 0.0f), glm::vec4(direction, tmax)};
}

LaneOrderFigures measure(render::RayTracer& tracer, const std::string& name, const OrderedRays& ordered,
                         render::TraceMode mode, int repeats) {
  LaneOrderFigures f;
  f.name = name;
  const render::TraceResult first = tracer.trace(ordered.rays, mode, true);
  double steps = 0.0, groupMax = 0.0;
  std::size_t groups = 0;
  for (std::size_t g = 0; g < ordered.rays.size(); g += kLanes) {
    std::uint32_t m = 0;
    bool any = false;
    for (std::size_t i = g; i < std::min(ordered.rays.size(), g + kLanes); ++i) {
      if (!ordered.real[i]) continue;
      any = true;
      ++f.rays;
      steps += first.steps[i];
      m = std::max(m, first.steps[i]);
    }
    if (any) {
      groupMax += m;
      ++groups;
    }
  }
  f.meanSteps = f.rays ? steps / static_cast<double>(f.rays) : 0.0;
  f.groupSteps = groups ? groupMax / static_cast<double>(groups) : 0.0;
  f.gpuMs = std::numeric_limits<double>::infinity();
  for (int k = 0; k < std::max(1, repeats); ++k) f.gpuMs = std::min(f.gpuMs, tracer.trace(ordered.rays, mode).gpuMs);
  return f;
}

// Pixel order: rows of the frame, or 4 x 2 tiles (Morton order within each 8 x 8 block), as 8
// consecutive lanes would take them.
std::vector<glm::uvec2> pixelOrder(const ObscuranceFrameWork& work, bool tiles) {
  std::vector<glm::uvec2> order;
  order.reserve(std::size_t(work.width) * work.height);
  if (!tiles) {
    for (std::uint32_t y = 0; y < work.height; ++y)
      for (std::uint32_t x = 0; x < work.width; ++x) order.push_back({x, y});
    return order;
  }
  for (std::uint32_t by = 0; by < work.height; by += 8)
    for (std::uint32_t bx = 0; bx < work.width; bx += 8)
      for (std::uint32_t k = 0; k < 64; ++k) {
        // De-interleave k's bits: x = bits 0, 2, 4; y = bits 1, 3, 5.
        const std::uint32_t x = bx + ((k & 1u) | ((k >> 1) & 2u) | ((k >> 2) & 4u));
        const std::uint32_t y = by + (((k >> 1) & 1u) | ((k >> 2) & 2u) | ((k >> 3) & 4u));
        if (x < work.width && y < work.height) order.push_back({x, y});
      }
  return order;
}

std::uint32_t spreadBits10(std::uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

} // namespace

std::vector<LaneOrderFigures> measureLaneOrders(render::RayTracer& tracer, const scene::Scene& scene,
                                                const ObscuranceFrameWork& work, int repeats) {
  std::vector<LaneOrderFigures> out;
  const glm::vec3 eye(work.camera.origin);
  // Camera rays of sample 0 in frame order, traced once for the hits.
  OrderedRays camera;
  for (glm::uvec2 p : pixelOrder(work, false)) {
    camera.rays.push_back(makeRay(eye, cameraRayDirection(work, p, 0), std::numeric_limits<float>::infinity()));
    camera.real.push_back(true);
  }
  const render::TraceResult hits = tracer.trace(camera.rays, render::TraceMode::Closest);
  out.push_back(measure(tracer, "camera rays, rows of 8 (the passes' order)", camera, render::TraceMode::Closest, repeats));
  OrderedRays cameraTiles;
  for (glm::uvec2 p : pixelOrder(work, true)) {
    cameraTiles.rays.push_back(camera.rays[std::size_t(p.y) * work.width + p.x]);
    cameraTiles.real.push_back(true);
  }
  out.push_back(measure(tracer, "camera rays, 4x2 tiles", cameraTiles, render::TraceMode::Closest, repeats));

  // Each pixel's obscurance rays (none where the camera ray missed).
  const std::uint32_t n = work.obscuranceRays;
  std::vector<std::vector<gpu::GpuRay>> perPixel(camera.rays.size());
  for (std::size_t i = 0; i < camera.rays.size(); ++i) {
    const gpu::GpuHit& h = hits.hits[i];
    if (h.primitive == gpu::kInvalidIndex || h.primitive == gpu::kTruncatedHit) continue;
    const auto& tri = scene.triangles[h.primitive];
    const glm::vec3 v0 = scene.positions[tri[0]], v1 = scene.positions[tri[1]], v2 = scene.positions[tri[2]];
    const glm::vec3 d(camera.rays[i].direction);
    glm::vec3 ng = glm::normalize(glm::cross(v1 - v0, v2 - v0));
    if (glm::dot(ng, d) > 0.0f) ng = -ng;
    const glm::uvec2 p(static_cast<std::uint32_t>(i % work.width), static_cast<std::uint32_t>(i / work.width));
    const ObscuranceRaySet set(work, p, 0, eye + h.t * d, ng, ng);
    for (std::uint32_t k = 0; k < n; ++k) perPixel[i].push_back(makeRay(set.origin(), set.direction(k), work.dMax));
  }
  // As the pass traces them: lanes = 8 consecutive pixels of the order, ray k of each together.
  auto passOrder = [&](const std::vector<glm::uvec2>& pixels) {
    OrderedRays o;
    for (std::size_t g = 0; g < pixels.size(); g += kLanes)
      for (std::uint32_t k = 0; k < n; ++k)
        for (std::size_t lane = 0; lane < kLanes; ++lane) {
          const std::size_t i = g + lane < pixels.size() ? std::size_t(pixels[g + lane].y) * work.width + pixels[g + lane].x
                                                         : std::numeric_limits<std::size_t>::max();
          const bool real = i < perPixel.size() && !perPixel[i].empty();
          o.rays.push_back(real ? perPixel[i][k] : makeRay(eye, glm::vec3(0.0f, 0.0f, 1.0f), 0.0f));
          o.real.push_back(real);
        }
    return o;
  };
  out.push_back(measure(tracer, "obscurance rays, rows of 8 (the pass's order)", passOrder(pixelOrder(work, false)),
                        render::TraceMode::Closest, repeats));
  out.push_back(measure(tracer, "obscurance rays, 4x2 tiles", passOrder(pixelOrder(work, true)), render::TraceMode::Closest,
                        repeats));
  // Sorted: origin cell (Morton code of a 1024^3 grid over the box) and direction octant.
  std::vector<std::pair<std::uint64_t, gpu::GpuRay>> keyed;
  const glm::vec3 lo = scene.bounds.lo, extent = glm::max(scene.bounds.extent(), glm::vec3(1e-20f));
  for (const auto& rays : perPixel)
    for (const gpu::GpuRay& r : rays) {
      const glm::vec3 u = glm::clamp((glm::vec3(r.origin) - lo) / extent, 0.0f, 0.999f) * 1024.0f;
      const std::uint64_t cell = spreadBits10(static_cast<std::uint32_t>(u.x)) |
                                 (spreadBits10(static_cast<std::uint32_t>(u.y)) << 1) |
                                 (spreadBits10(static_cast<std::uint32_t>(u.z)) << 2);
      const std::uint64_t octant = (r.direction.x < 0.0f ? 1u : 0u) | (r.direction.y < 0.0f ? 2u : 0u) |
                                   (r.direction.z < 0.0f ? 4u : 0u);
      keyed.push_back({(cell << 3) | octant, r});
    }
  auto sortedBy = [&](const std::string& name, auto key) {
    std::stable_sort(keyed.begin(), keyed.end(), [&](const auto& a, const auto& b) { return key(a.first) < key(b.first); });
    OrderedRays sorted;
    for (const auto& [k, ray] : keyed) {
      sorted.rays.push_back(ray);
      sorted.real.push_back(true);
    }
    out.push_back(measure(tracer, name, sorted, render::TraceMode::Closest, repeats));
  };
  sortedBy("obscurance rays, sorted by origin cell, then octant", [](std::uint64_t k) { return k; });
  sortedBy("obscurance rays, sorted by octant, then origin cell",
           [](std::uint64_t k) { return ((k & 7u) << 60) | (k >> 3); });
  return out;
}

} // namespace obscura::bench
