// photo_gather.cpp — see photo_gather.h.
#include "recover/photo_gather.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <unordered_map>

#include <glm/gtc/constants.hpp>

#include "core/luminance.h"
#include "core/parallel_for.h"
#include "recover/pixel_footprint.h"
#include "recover/recovery_scene.h"
#include "render/gpu_ray_batch.h"
#include "render/scene_data/camera_grid.h"
#include "render/scene_data/scene_buffers.h"

namespace obscura::recover {
namespace {

// The host's share of the gather, on every core, a block of rays at a time.
constexpr std::size_t kHostBlock = 4096;

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

// The interpolated vertex normal at `hit`, turned to the side of `geometric` (the side the ray
// came from), as surface.glsl's shadingNormal; the geometric normal where the scene has none.
glm::vec3 shadingNormal(const scene::Scene& room, const bvh::Hit& hit, const glm::vec3& geometric) {
  if (room.normals.size() != room.positions.size()) return geometric;
  const glm::uvec3 tri = room.triangles[hit.primitive];
  const glm::vec3 n =
      (1.0f - hit.u - hit.v) * room.normals[tri.x] + hit.u * room.normals[tri.y] + hit.v * room.normals[tri.z];
  const float length = glm::length(n);
  if (!(length > 0.0f)) return geometric;
  return glm::dot(n, geometric) < 0.0f ? -n / length : n / length;
}

// The box of the points the camera sees, from the 2nd to the 98th percentile on each axis: a
// room's model may stand in far larger geometry (the classroom's ground, 221 m across its 9 m
// room), and a grid over the model's bounds made one cell of the whole room.
scene::Bounds seenBounds(const PixelGeometry& pixels) {
  std::array<std::vector<float>, 3> axes;
  for (std::size_t p = 0; p < pixels.position.size(); ++p)
    if (pixels.object[p] >= 0)
      for (int a = 0; a < 3; ++a) axes[std::size_t(a)].push_back(pixels.position[p][a]);
  scene::Bounds b;
  if (axes[0].empty()) return b;
  b.lo = b.hi = glm::vec3(0.0f);
  for (int a = 0; a < 3; ++a) {
    std::vector<float>& v = axes[std::size_t(a)];
    const auto at = [&](double q) {
      const auto k = static_cast<std::ptrdiff_t>(q * double(v.size() - 1));
      std::nth_element(v.begin(), v.begin() + k, v.end());
      return v[std::size_t(k)];
    };
    b.lo[a] = at(0.02);
    b.hi[a] = at(0.98);
  }
  return b;
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
                         std::uint32_t seed, int smoothRadius, std::uint32_t hiddenBounces, float exactShare)
    : geometry_(&pixels), smoothRadius_(smoothRadius), pixels_(pixels.position.size()), shots_(shots.size()),
      raysPerPixel_(raysPerPixel), hiddenBounces_(hiddenBounces) {
  if (hiddenBounces > kMaxHiddenBounces) throw std::invalid_argument("PhotoGather: hiddenBounces above kMaxHiddenBounces");
  const std::vector<std::uint32_t> objectOf = triangleObjects(room);
  const float scale = render::sceneScale(room.bounds);
  const float offset = 1e-4f * scale;       // ray origins off the surface
  const float samePlane = 2e-3f * scale;    // a seen pixel's point within this of the hit's plane
  // The cut's regions: an object's part facing one of the six axis directions (the two faces of
  // a thin wall see different rooms) in one cubic cell of a grid over what the camera sees, the
  // cells past its edges gathered into one layer around it.
  scene::Bounds seen = seenBounds(pixels);
  if (seen.empty()) seen = room.bounds;
  const glm::vec3 extent = seen.extent();
  const float cell = std::max({extent.x, extent.y, extent.z, 1e-6f * scale}) / kCutCells;
  const glm::ivec3 regionCells = glm::max(glm::ivec3(glm::ceil(extent / cell)), glm::ivec3(1)) + 2;
  std::unordered_map<std::uint64_t, std::uint32_t> regionAt;
  const auto regionOf = [&](std::uint32_t object, const glm::vec3& point, const glm::vec3& normal) {
    const glm::ivec3 c =
        glm::clamp(glm::ivec3(glm::floor((point - seen.lo) / cell)) + 1, glm::ivec3(0), regionCells - 1);
    const glm::vec3 a = glm::abs(normal);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    const std::uint64_t facing = std::uint64_t(2 * axis + (normal[axis] < 0.0f ? 1 : 0));
    const std::uint64_t key =
        (((std::uint64_t(object) * 6u + facing) * std::uint64_t(regionCells.z) + std::uint64_t(c.z)) *
             std::uint64_t(regionCells.y) + std::uint64_t(c.y)) * std::uint64_t(regionCells.x) + std::uint64_t(c.x);
    const auto [at, added] = regionAt.try_emplace(key, static_cast<std::uint32_t>(regionObject_.size()));
    if (added) regionObject_.push_back(object);
    return at->second;
  };
  seenStart_.reserve(pixels_ + 1);
  hiddenStart_.reserve(pixels_);
  hiddenEnd_.reserve(pixels_);

  // A hit: the pixel that shows it, or (-1) its object, point and normal facing the ray.
  struct Classified {
    std::int64_t seenPixel = -1;
    std::uint32_t object = 0;
    glm::vec3 lit{0.0f}, normal{0.0f}; // the point just off the surface on the ray's side
  };
  const auto classify = [&](const bvh::Hit& hit, const glm::vec3& dir) {
    Classified c;
    const glm::uvec3 tri = room.triangles[hit.primitive];
    const glm::vec3 a = room.positions[tri.x];
    const glm::vec3 q = a + hit.u * (room.positions[tri.y] - a) + hit.v * (room.positions[tri.z] - a);
    glm::vec3 nq = glm::normalize(glm::cross(room.positions[tri.y] - a, room.positions[tri.z] - a));
    if (glm::dot(nq, dir) > 0.0f) nq = -nq; // the side facing the ray reflects towards its origin
    c.object = objectOf[hit.primitive];
    const std::int64_t v = projectToPixel(camera, pixels.width, pixels.height, q);
    if (v >= 0) {
      const auto vi = static_cast<std::size_t>(v);
      // The camera sees Q's side if that pixel shows the same object on the same plane, from
      // the same side (its normal faces the camera, so it must agree with nq).
      if (pixels.object[vi] == static_cast<std::int32_t>(c.object) &&
          std::abs(glm::dot(pixels.position[vi] - q, nq)) < samePlane && glm::dot(pixels.normal[vi], nq) > 0.9f) {
        c.seenPixel = v;
        return c;
      }
    }
    c.lit = q + offset * nq;
    c.normal = nq;
    return c;
  };
  // Every hit of a batch classified on every core (classify reads the scene and the camera
  // alone); the pass over them that numbers the hidden vertices stays in order, on one.
  const auto blocks = [](std::size_t n) { return (n + kHostBlock - 1) / kHostBlock; };
  const auto classifyAll = [&](const std::vector<bvh::Hit>& hits, const std::vector<bvh::Ray>& from) {
    std::vector<Classified> out(hits.size());
    parallelFor(blocks(hits.size()), [&](std::size_t b) {
      for (std::size_t r = b * kHostBlock; r < std::min(hits.size(), (b + 1) * kHostBlock); ++r)
        if (hits[r].hit()) out[r] = classify(hits[r], from[r].direction);
    });
    return out;
  };
  // The shadow rays from a hidden point to every shot's lamp, their results written to
  // direct[at + i] after the batch is traced.
  struct PendingDirect {
    std::vector<float>* direct;
    std::size_t at;
    float unblocked; // the lamp's light there if nothing is in the way
  };
  std::vector<PendingDirect> pending;
  std::vector<bvh::Ray> shadowRays;
  // A path's first hidden vertex traces a shadow ray to every lamp that gives it at least
  // `exactShare` of its unoccluded light, u_i >= exactShare sum u, and one more to a lamp of the
  // rest, chosen by u_i / (sum of the rest's u), its result weighted back to that sum (so each lamp's
  // mean is kept). A deeper one, whose light comes back through one or more reflections more
  // (weight R^depth), traces that one alone. A ray to every lamp a first vertex faces, most of
  // them far or grazing, made the staircase's gather 4.9 s against 3.8 s, for the same RMSE to
  // +-0.0002 on every room; at the deeper vertices it had cost 4.9 s more (BENCHMARKS).
  std::vector<float> unblocked(shots.size());
  const auto queueDirect = [&](const Classified& c, std::vector<float>& direct, bool firstVertex, std::uint32_t vertex) {
    float total = 0.0f;
    for (std::size_t i = 0; i < shots.size(); ++i) {
      const glm::vec3 toLamp = shots[i].position - c.lit;
      const float d2 = glm::dot(toLamp, toLamp);
      const float cosine = glm::dot(c.normal, toLamp) / std::sqrt(d2);
      unblocked[i] = cosine > 0.0f ? shots[i].intensity * cosine / (glm::pi<float>() * d2) : 0.0f;
      total += unblocked[i];
    }
    const std::size_t first = direct.size();
    direct.resize(first + shots.size(), 0.0f);
    const auto queue = [&](std::size_t i, float weight) {
      pending.push_back({&direct, first + i, weight});
      shadowRays.push_back({c.lit, shots[i].position - c.lit, 0.0f, 1.0f - 1e-4f});
    };
    const auto exact = [&](std::size_t i) {
      return firstVertex && unblocked[i] > 0.0f && unblocked[i] >= exactShare * total;
    };
    float rest = 0.0f; // the lamps' light that no exact ray takes
    for (std::size_t i = 0; i < shots.size(); ++i) {
      if (exact(i)) queue(i, unblocked[i]);
      else rest += unblocked[i];
    }
    if (!(rest > 0.0f)) return;
    float u = unit(hash(vertex ^ hash(seed + 97u))) * rest;
    std::size_t chosen = shots.size();
    for (std::size_t i = 0; i < shots.size(); ++i) {
      if (exact(i) || !(unblocked[i] > 0.0f)) continue;
      chosen = i; // the last of the rest, should rounding leave u above every share
      if (u < unblocked[i]) break;
      u -= unblocked[i];
    }
    queue(chosen, rest);
  };
  const auto cosineRay = [](const glm::vec3& origin, const glm::vec3& n, float u1, float u2) {
    glm::vec3 t, b;
    frame(n, t, b);
    const float r = std::sqrt(u1), phi = 2.0f * glm::pi<float>() * u2;
    return bvh::Ray{origin,
                    r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - u1)) * n};
  };

  // The pixels a chunk at a time, each chunk's rays traced together (one dispatch on a device):
  // its gather rays; the paths on from its hidden hits, a ray per vertex and depth; then the shadow
  // rays from all of them to every shot's lamp.
  const std::size_t pixelsPerChunk = std::max<std::size_t>(1, kRaysPerBatch / std::max(raysPerPixel, 1u));
  std::vector<bvh::Ray> gatherRays, bounceRays;
  struct Active {
    std::uint32_t vertex;
    glm::vec3 lit, normal;
  };
  std::vector<Active> active;
  // The gather rays start where camera rays through jittered points of their pixel meet the room
  // (kPointsPerPixel of them, each ray from point k mod that), so B is the mean over the pixel's
  // footprint, as the rendered direct light D is. The pixel's mean point (the position AOV) is no
  // surface point where the footprint is curved or crosses an edge: on a chair's tubular frame it
  // lies inside the tube, and rays from there lit it from the tube's inside (classroom: 57 % of a
  // frame pixel's hidden hits were its own tube, B 0.6 of path tracing's).
  const render::GridCamera view = pixelCamera(camera, pixels.width, pixels.height);
  std::vector<bvh::Ray> cameraRays;
  const std::uint32_t points = std::min(raysPerPixel, kPointsPerPixel);
  // Each point jittered in a cell of a grid over the pixel (2 x 2 for 4 points).
  const auto cells = static_cast<std::uint32_t>(std::ceil(std::sqrt(float(points))));
  for (std::size_t first = 0; first < pixels_; first += pixelsPerChunk) {
    const std::size_t last = std::min(pixels_, first + pixelsPerChunk);
    cameraRays.clear();
    for (std::size_t p = first; p < last; ++p) {
      if (pixels.object[p] < 0) continue;
      const float x = float(p % std::size_t(pixels.width)), y = float(p / std::size_t(pixels.width));
      for (std::uint32_t k = 0; k < points; ++k) {
        const std::uint32_t hp = hash((static_cast<std::uint32_t>(p) * points + k) ^ hash(seed + 7u));
        const float jx = (float(k % cells) + unit(hp)) / float(cells);
        const float jy = (float(k / cells) + unit(hash(hp))) / float(cells);
        cameraRays.push_back(render::gridRay(view, (x + jx) / float(pixels.width), (y + jy) / float(pixels.height), 1));
      }
    }
    const std::vector<bvh::Hit> surface = rays.closest(cameraRays);
    // Where each camera ray meets the room and the shading normal there, once per point (each
    // point starts raysPerPixel / points gather rays), on every core.
    std::vector<std::optional<render::GridHit>> starts(cameraRays.size());
    std::vector<glm::vec3> shadings(cameraRays.size());
    parallelFor(blocks(cameraRays.size()), [&](std::size_t b) {
      for (std::size_t at = b * kHostBlock; at < std::min(cameraRays.size(), (b + 1) * kHostBlock); ++at) {
        starts[at] = render::gridHit(room, cameraRays[at], surface[at]);
        if (starts[at]) shadings[at] = shadingNormal(room, surface[at], starts[at]->normal);
      }
    });
    gatherRays.clear();
    std::size_t pixelFirst = 0; // the pixel's first camera ray
    for (std::size_t p = first; p < last; ++p) {
      if (pixels.object[p] < 0) continue;
      // Stratified in the first dimension, van der Corput in the second, shifted per pixel.
      const std::uint32_t h = hash(static_cast<std::uint32_t>(p) ^ hash(seed));
      const float shift1 = unit(h), shift2 = unit(hash(h));
      for (std::uint32_t k = 0; k < raysPerPixel; ++k) {
        const std::size_t at = pixelFirst + k % points;
        const std::optional<render::GridHit>& start = starts[at];
        if (!start) { // this point of the pixel sees nothing: no light, as none in D there
          gatherRays.push_back({cameraRays[at].origin, cameraRays[at].direction, 0.0f, 0.0f});
          continue;
        }
        const float u1 = std::fmod((float(k) + 0.5f) / float(raysPerPixel) + shift1, 1.0f);
        const float u2 = std::fmod(radicalInverse2(k) + shift2, 1.0f);
        // Cosine-distributed about the shading normal, as the renderer's D and the photographs'
        // diffuse surfaces reflect; one below the surface's own plane sees its inside: black.
        bvh::Ray gatherRay = cosineRay(start->position + offset * start->normal, shadings[at], u1, u2);
        if (!(glm::dot(gatherRay.direction, start->normal) > 0.0f)) gatherRay.tmax = 0.0f;
        gatherRays.push_back(gatherRay);
      }
      pixelFirst += points;
    }
    const std::vector<bvh::Hit> hits = rays.closest(gatherRays);
    const std::vector<Classified> classes = classifyAll(hits, gatherRays);
    shadowRays.clear();
    pending.clear();
    bounceRays.clear();
    std::size_t ray = 0;
    for (std::size_t p = first; p < last; ++p) {
      seenStart_.push_back(static_cast<std::uint32_t>(seen_.size()));
      hiddenStart_.push_back(static_cast<std::uint32_t>(hiddenObject_.size()));
      if (pixels.object[p] < 0) {
        hiddenEnd_.push_back(hiddenStart_.back());
        continue;
      }
      rays_ += raysPerPixel;
      for (std::uint32_t k = 0; k < raysPerPixel; ++k, ++ray) {
        if (!hits[ray].hit()) continue; // leaves the scene: black
        const Classified& c = classes[ray];
        if (c.seenPixel >= 0) {
          seen_.push_back(static_cast<std::uint32_t>(c.seenPixel));
          continue;
        }
        active.push_back({static_cast<std::uint32_t>(hiddenObject_.size()), c.lit, c.normal});
        hiddenObject_.push_back(c.object);
        hiddenRegion_.push_back(regionOf(c.object, c.lit, c.normal));
        next_.push_back(kTruncated);
        queueDirect(c, hiddenDirect_, true, static_cast<std::uint32_t>(hiddenObject_.size() - 1));
        ++firstHidden_;
      }
      hiddenEnd_.push_back(static_cast<std::uint32_t>(hiddenObject_.size()));
    }
    // Each hidden vertex's own indirect light: one more cosine-distributed ray, up to
    // hiddenBounces_ vertices deep. It ends at a surface the camera sees (the photograph), or
    // leaves the room (black), or is cut at the last depth (its object's c_o).
    for (std::uint32_t depth = 0; depth < hiddenBounces_ && !active.empty(); ++depth) {
      bounceRays.clear();
      for (const Active& a : active) {
        const std::uint32_t hb = hash(a.vertex ^ hash(seed + 1u + depth));
        bounceRays.push_back(cosineRay(a.lit, a.normal, unit(hb), unit(hash(hb))));
      }
      const std::vector<bvh::Hit> bounces = rays.closest(bounceRays);
      const std::vector<Classified> bounceClasses = classifyAll(bounces, bounceRays);
      std::vector<Active> deeper;
      for (std::size_t k = 0; k < bounces.size(); ++k) {
        const std::uint32_t v = active[k].vertex;
        if (!bounces[k].hit()) {
          next_[v] = kEscaped;
          continue;
        }
        const Classified& c = bounceClasses[k];
        if (c.seenPixel >= 0) {
          next_[v] = kSeenFlag | static_cast<std::uint32_t>(c.seenPixel);
          continue;
        }
        const auto u = static_cast<std::uint32_t>(hiddenObject_.size());
        next_[v] = u;
        hiddenObject_.push_back(c.object);
        hiddenRegion_.push_back(regionOf(c.object, c.lit, c.normal));
        next_.push_back(kTruncated);
        queueDirect(c, hiddenDirect_, false, u);
        deeper.push_back({u, c.lit, c.normal});
      }
      active = std::move(deeper);
    }
    active.clear();
    // The vectors the pending entries point into are not resized from here on.
    const std::vector<float> blocked = rays.blockedAt(shadowRays);
    for (std::size_t i = 0; i < pending.size(); ++i)
      if (std::isinf(blocked[i])) (*pending[i].direct)[pending[i].at] = pending[i].unblocked;
  }
  seenStart_.push_back(static_cast<std::uint32_t>(seen_.size()));
  // Shot by shot from here on: a gather reads one shot's values of every vertex (indirect() lights
  // one lamp at a time), and so reads a sixth of the memory it would read with them interleaved.
  const std::size_t vertices = hiddenObject_.size();
  std::vector<float> byShot(hiddenDirect_.size());
  for (std::size_t v = 0; v < vertices; ++v)
    for (std::size_t i = 0; i < shots_; ++i) byShot[i * vertices + v] = hiddenDirect_[v * shots_ + i];
  hiddenDirect_ = std::move(byShot);
}

std::vector<std::size_t> PhotoGather::litShots(const std::vector<glm::vec3>& lampColour) const {
  std::vector<std::size_t> lit;
  for (std::size_t i = 0; i < shots_; ++i)
    if (lampColour.at(i) != glm::vec3(0.0f)) lit.push_back(i);
  return lit;
}

PhotoGather PhotoGather::onDevice(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                                  const scene::Camera& camera, const PixelGeometry& pixels,
                                  const std::vector<Shot>& shots, std::uint32_t raysPerPixel, std::uint32_t seed,
                                  int smoothRadius, std::uint32_t hiddenBounces) {
  const render::SceneBuffers buffers(context, room, bvh);
  render::GpuRayBatch rays(context, buffers, render::TraceShape::forDevice(context, buffers.traversal()));
  return PhotoGather(room, rays, camera, pixels, shots, raysPerPixel, seed, smoothRadius, hiddenBounces);
}

std::vector<std::vector<glm::vec3>> PhotoGather::indirect(const std::vector<Shot>& shots,
                                                          const std::vector<glm::vec3>& objectReflectance,
                                                          const std::vector<Cut>& cut, std::vector<Cut>* settled,
                                                          std::vector<std::vector<float>>* modelled) const {
  std::vector<std::vector<glm::vec3>> out(shots_);
  if (settled) settled->assign(shots_, Cut());
  if (modelled) modelled->assign(shots_, {});
  // The shots' gathers are independent re-sums of the same paths: one per core.
  parallelFor(shots_, [&](std::size_t i) {
    std::vector<glm::vec3> lampColour(shots_, glm::vec3(0.0f));
    lampColour[i] = shots[i].color;
    out[i] = gather(shots[i].radiance, lampColour, objectReflectance, cut.at(i), settled ? &(*settled)[i] : nullptr,
                    modelled ? &(*modelled)[i] : nullptr);
  });
  return out;
}

std::vector<glm::vec3> PhotoGather::gather(const std::vector<glm::vec3>& radiance,
                                           const std::vector<glm::vec3>& lampColour,
                                           const std::vector<glm::vec3>& objectReflectance, const Cut& cut,
                                           Cut* settled, std::vector<float>* modelled) const {
  CutSums sums;
  const std::vector<glm::vec3> hidden =
      hiddenRadiance(radiance, lampColour, objectReflectance, cut, settled ? &sums : nullptr);
  std::vector<glm::vec3> out(pixels_, glm::vec3(0.0f)), deep;
  if (modelled) deep.assign(pixels_, glm::vec3(0.0f));
  const std::vector<std::size_t> lit = litShots(lampColour);
  const std::size_t vertices = hiddenObject_.size();
  const float perRay = 1.0f / float(raysPerPixel_);
  for (std::size_t p = 0; p < pixels_; ++p) {
    glm::vec3 sum(0.0f), deeper(0.0f);
    for (std::uint32_t k = seenStart_[p]; k < seenStart_[p + 1]; ++k) sum += radiance[seen_[k]];
    for (std::uint32_t k = hiddenStart_[p]; k < hiddenEnd_[p]; ++k) {
      sum += hidden[k];
      if (!modelled) continue;
      // What the hidden hit passes on beyond its own direct light (a shadow ray per lamp).
      glm::vec3 direct(0.0f);
      for (const std::size_t i : lit) direct += hiddenDirect_[i * vertices + k] * lampColour[i];
      deeper += hidden[k] - direct * objectReflectance[hiddenObject_[k]];
    }
    out[p] = sum * perRay;
    if (modelled) deep[p] = deeper * perRay;
  }
  if (smoothRadius_ > 0) {
    out = smoothOnSurfaces(out, *geometry_, smoothRadius_);
    if (modelled) deep = smoothOnSurfaces(deep, *geometry_, smoothRadius_);
  }
  if (modelled) {
    modelled->assign(pixels_, 0.0f);
    for (std::size_t p = 0; p < pixels_; ++p) {
      const float all = luminance(out[p]);
      if (all > 0.0f) (*modelled)[p] = std::clamp(luminance(deep[p]) / all, 0.0f, 1.0f);
    }
  }
  if (settled) {
    // The prior an object with few vertices of its own leans on: the pixels' mean B now.
    glm::dvec3 sumB(0.0);
    std::size_t surfaces = 0;
    for (std::size_t p = 0; p < pixels_; ++p)
      if (geometry_->object[p] >= 0) {
        sumB += glm::dvec3(out[p]);
        ++surfaces;
      }
    const glm::dvec3 b = surfaces > 0 ? sumB / double(surfaces) : glm::dvec3(0.0);
    settled->object.resize(cut.object.size());
    for (std::size_t o = 0; o < cut.object.size(); ++o)
      settled->object[o] = glm::vec3((sums.incoming[o] + kCutPrior * b) / (sums.paths[o] + kCutPrior));
    settled->region.resize(regionObject_.size());
    for (std::size_t r = 0; r < regionObject_.size(); ++r) {
      const glm::dvec3 object(settled->object[regionObject_[r]]);
      settled->region[r] = glm::vec3((sums.regionIncoming[r] + kCutPrior * object) / (sums.regionPaths[r] + kCutPrior));
    }
  }
  return out;
}

std::vector<glm::vec3> PhotoGather::hiddenRadiance(const std::vector<glm::vec3>& radiance,
                                                   const std::vector<glm::vec3>& lampColour,
                                                   const std::vector<glm::vec3>& objectReflectance, const Cut& cut,
                                                   CutSums* sums) const {
  // L(v) = R_o(v) (sum_i direct_i(v) lamp_i + L_in(v)), L_in(v) the next vertex's L, the
  // photograph where the camera sees it, 0 where the ray left, c_o(v) where the path was cut.
  const std::size_t vertices = hiddenObject_.size();
  std::vector<glm::vec3> out(vertices);
  const std::vector<std::size_t> lit = litShots(lampColour);
  if (sums) {
    sums->incoming.assign(cut.object.size(), glm::dvec3(0.0));
    sums->paths.assign(cut.object.size(), 0.0);
    sums->regionIncoming.assign(regionObject_.size(), glm::dvec3(0.0));
    sums->regionPaths.assign(regionObject_.size(), 0.0);
  }
  const bool regional = cut.region.size() == regionObject_.size();
  for (std::size_t v = vertices; v-- > 0;) {
    const std::uint32_t n = next_[v], o = hiddenObject_[v], r = hiddenRegion_[v];
    const glm::vec3 in = n == kEscaped ? glm::vec3(0.0f)
                         : n == kTruncated ? (regional ? cut.region[r] : cut.object[o])
                         : (n & kSeenFlag) != 0 ? radiance[n & ~kSeenFlag]
                                                : out[n];
    if (sums && n != kTruncated) {
      sums->incoming[o] += glm::dvec3(in);
      sums->paths[o] += 1.0;
      sums->regionIncoming[r] += glm::dvec3(in);
      sums->regionPaths[r] += 1.0;
    }
    glm::vec3 light = in;
    for (const std::size_t i : lit) light += hiddenDirect_[i * vertices + v] * lampColour[i];
    out[v] = light * objectReflectance[o];
  }
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
