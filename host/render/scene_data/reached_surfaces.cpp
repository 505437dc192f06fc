#include "render/scene_data/reached_surfaces.h"

#include "render/scene_data/camera_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace obscura::render {

// The streams of a light's measurement: one per ray (or per surface sample, whose tries share it).
enum class Stream : std::uint32_t { LightRay = 1, Bounce = 2, Sample = 3, Seen = 4, SeenGrid = 5, SampleCount = 6, SamplePoint = 7,
                                    SeenGather = 8 };

// A counter-based generator (splitmix64, Steele, Lea & Flood 2014) for one stream: cheap to start
// at any (light, stream, index), so that every ray has numbers of its own.
class StreamRng {
public:
  StreamRng(std::uint32_t lightSeed, Stream stream, std::uint32_t index)
      : state_((std::uint64_t{lightSeed} << 32) ^ (std::uint64_t{static_cast<std::uint32_t>(stream)} << 28) ^ index) {
    next64(); // decorrelate neighbouring seeds
  }
  float next() { return static_cast<float>(next64() >> 40) * 0x1p-24f; } // uniform in [0, 1)
  std::uint32_t below(std::uint32_t n) { return static_cast<std::uint32_t>((next64() >> 32) * n >> 32); }
  // Where the stream stands, to go on from there later (ReachRays::landingTryDraws).
  std::uint64_t state() const { return state_; }
  static StreamRng resumed(std::uint64_t state) { return StreamRng(state); }

private:
  explicit StreamRng(std::uint64_t state) : state_(state) {}
  std::uint64_t next64() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  std::uint64_t state_;
};

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();


struct Frame {
  glm::vec3 t, b, n;
};

Frame frameAround(glm::vec3 n) {
  glm::vec3 a = std::abs(n.x) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  glm::vec3 t = glm::normalize(glm::cross(a, n));
  return {t, glm::cross(n, t), n};
}

glm::vec3 cosineDirection(glm::vec3 n, float u1, float u2) {
  Frame f = frameAround(n);
  float r = std::sqrt(u1), phi = 2.0f * kPi * u2;
  return r * std::cos(phi) * f.t + r * std::sin(phi) * f.b + std::sqrt(std::max(0.0f, 1.0f - u1)) * f.n;
}

glm::vec3 sphereDirection(float u1, float u2) {
  float z = 1.0f - 2.0f * u1, r = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// A point that emits, with the side it emits to (area lights), or a punctual light's position.
struct LightPoint {
  glm::vec3 position;
  glm::vec3 normal{0.0f}; // 0: punctual
  bool twoSided = false;
  bool directional = false;
  glm::vec3 direction{0.0f}; // directional: the way the light travels
};

LightPoint samplePoint(const LightSet& lights, std::size_t s, StreamRng& rng, const scene::Bounds& bounds) {
  auto uni = [](StreamRng& r) { return r.next(); };
  const gpu::GpuLight& l = lights.lights[s];
  LightPoint p;
  if (l.info.x == gpu::kLightArea) {
    float u = uni(rng);
    // The first emitter whose cumulative share (v0.w) exceeds u, else the last: a light group may
    // hold thousands of triangles.
    const std::uint32_t first = l.info.y, count = l.info.z;
    const auto begin = lights.emitters.begin() + first, last = begin + (count - 1);
    const std::uint32_t e = first + static_cast<std::uint32_t>(
        std::upper_bound(begin, last, u, [](float x, const gpu::GpuEmitter& em) { return x < em.v0.w; }) - begin);
    const auto& em = lights.emitters[e];
    float r = std::sqrt(uni(rng)), v = uni(rng);
    glm::vec3 a(em.v0), b(em.v1), c(em.v2);
    p.position = (1.0f - r) * a + r * (1.0f - v) * b + r * v * c;
    glm::vec3 n = glm::cross(b - a, c - a);
    float len = glm::length(n);
    p.normal = len > 0.0f ? n / len : glm::vec3(0, 0, 1);
    p.twoSided = em.v2.w != 0.0f;
  } else if (l.info.x == gpu::kLightBackground) {
    // A point of the sky: on the scene's bounding sphere, emitting inwards.
    glm::vec3 centre = 0.5f * (bounds.lo + bounds.hi);
    float radius = 0.5f * glm::length(bounds.hi - bounds.lo) + 1e-3f;
    glm::vec3 d = sphereDirection(uni(rng), uni(rng));
    p.position = centre + radius * d;
    p.normal = -d;
  } else if (l.info.x == gpu::kLightDirectional) {
    // From a disk as wide as the scene's bounding sphere, outside it, towards the scene.
    glm::vec3 dir = glm::normalize(glm::vec3(l.direction));
    glm::vec3 centre = 0.5f * (bounds.lo + bounds.hi);
    float radius = 0.5f * glm::length(bounds.hi - bounds.lo) + 1e-3f;
    Frame f = frameAround(dir);
    float r = radius * std::sqrt(uni(rng)), phi = 2.0f * kPi * uni(rng);
    p.position = centre - 2.0f * radius * dir + r * std::cos(phi) * f.t + r * std::sin(phi) * f.b;
    p.directional = true;
    p.direction = dir;
  } else {
    p.position = glm::vec3(l.position);
  }
  return p;
}

// A direction the light at `p` emits into (cosine for area lights, uniform or within the cone for
// punctual ones); false when a spot gave none.
bool emitDirection(const LightSet& lights, std::size_t s, const LightPoint& p, StreamRng& rng, glm::vec3& d) {
  auto uni = [](StreamRng& r) { return r.next(); };
  const gpu::GpuLight& l = lights.lights[s];
  if (p.directional) {
    d = p.direction;
    return true;
  }
  if (l.info.x == gpu::kLightArea || l.info.x == gpu::kLightBackground) {
    glm::vec3 n = p.twoSided && uni(rng) < 0.5f ? -p.normal : p.normal;
    d = cosineDirection(n, uni(rng), uni(rng));
    return true;
  }
  for (int tries = 0; tries < 64; ++tries) {
    d = sphereDirection(uni(rng), uni(rng));
    if (l.info.x != gpu::kLightSpot || glm::dot(d, glm::vec3(l.direction)) >= l.params.w) return true;
  }
  return false;
}

float largestExtent(const scene::Bounds& bounds) {
  glm::vec3 e = bounds.extent();
  float largest = std::max(e.x, std::max(e.y, e.z));
  return largest > 0.0f && std::isfinite(largest) ? largest : 1.0f;
}

// At least ~32 ulps of the point's largest coordinate: a scene far from the origin, or scaled by
// 1e4, keeps its rays off their own surfaces.
float offsetAt(glm::vec3 p, float offset) {
  return std::max(offset, 4e-6f * std::max(std::abs(p.x), std::max(std::abs(p.y), std::abs(p.z))));
}

// `p` moved off its surface (normal `n`) by `offset` (at least offsetAt's) to the side `towards` lies on.
glm::vec3 offsetToward(glm::vec3 p, glm::vec3 n, glm::vec3 towards, float offset) {
  const float o = offsetAt(p, offset);
  return p + (glm::dot(n, towards - p) >= 0.0f ? o : -o) * n;
}

// Whether the segment origin + t direction, t in [0, tmax] (tmax may be infinite), meets the box:
// the slab test, an axis the direction runs parallel to tested on the origin alone.
bool segmentMeetsBox(glm::vec3 origin, glm::vec3 direction, float tmax, const scene::Bounds& box) {
  // First the segment's own box against it (most of a replay's segments pass far from a moved
  // object): no division.
  if (std::isfinite(tmax)) {
    const glm::vec3 end = origin + tmax * direction;
    const glm::vec3 lo = glm::min(origin, end), hi = glm::max(origin, end);
    if (glm::any(glm::lessThan(hi, box.lo)) || glm::any(glm::greaterThan(lo, box.hi))) return false;
  }
  float t0 = 0.0f, t1 = tmax;
  for (int axis = 0; axis < 3; ++axis) {
    const float o = origin[axis], d = direction[axis];
    if (d == 0.0f) {
      if (o < box.lo[axis] || o > box.hi[axis]) return false;
      continue;
    }
    const float a = (box.lo[axis] - o) / d, b = (box.hi[axis] - o) / d;
    t0 = std::max(t0, std::min(a, b));
    t1 = std::min(t1, std::max(a, b));
    if (t0 > t1) return false;
  }
  return true;
}

std::uint32_t lightSeed(const std::string& name) {
  // Seeded by the light's name, not its index: the same light gets the same estimate in a scene
  // with other lights added or removed.
  std::uint32_t seed = 2166136261u; // FNV-1a
  for (unsigned char c : name) seed = (seed ^ c) * 16777619u;
  return seed;
}

} // namespace

float obscuranceRho(float d, float dMax, std::uint32_t kind, float tau) {
  const float x = std::clamp(d / dMax, 0.0f, 1.0f);
  if (kind == gpu::kRhoAo) return x >= 1.0f ? 1.0f : 0.0f;
  if (kind == gpu::kRhoExp) return (1.0f - std::exp(-tau * x)) / (1.0f - std::exp(-tau));
  return std::sqrt(x);
}

ReachedSurfaces::ReachedSurfaces(const scene::Scene& scene, const bvh::Bvh& bvh, const std::vector<glm::vec3>& reflectance,
                                 bool copyBvh)
    : scene_(&scene), bvhCopy_(copyBvh ? std::optional<bvh::Bvh>(bvh) : std::nullopt),
      callersBvh_(&bvh), reflectance_(reflectance), bounds_(scene.bounds),
      offset_(1e-5f * largestExtent(scene.bounds)) {
  std::vector<double> area(scene.triangles.size());
  for (std::size_t t = 0; t < scene.triangles.size(); ++t) {
    const glm::uvec3 tri = scene.triangles[t];
    glm::dvec3 a(scene.positions[tri.x]), b(scene.positions[tri.y]), c(scene.positions[tri.z]);
    area[t] = 0.5 * glm::length(glm::cross(b - a, c - a));
    totalArea_ += area[t];
  }
  if (!(totalArea_ > 0.0)) return;
  // Uniform by area, kSurfaceSamples in expectation, drawn triangle by triangle: triangle t gets
  // floor(N a_t / A + xi_t) points (xi_t its own uniform number), point k of it at barycentrics of
  // its own. So an edit that appends triangles (a quad, an inserted object), or moves some, leaves
  // nearly every point where it was (only triangles whose count crosses its xi_t gain or lose one),
  // and the points keep their numbers: a re-measurement matches them by (t, k) (remeasure).
  for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
    const double expected = static_cast<double>(kSurfaceSamples) * area[t] / totalArea_;
    const auto count = static_cast<std::uint32_t>(expected + StreamRng(0x5eedu, Stream::SampleCount, t).next());
    if (count == 0) continue;
    const glm::uvec3 tri = scene.triangles[t];
    glm::vec3 a = scene.positions[tri.x], b = scene.positions[tri.y], c = scene.positions[tri.z];
    glm::vec3 n = glm::cross(b - a, c - a);
    const float len = glm::length(n);
    if (!(len > 0.0f)) continue;
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint64_t key = std::uint64_t{t} << 32 | k;
      StreamRng rng(0x5eedu, Stream::SamplePoint, sampleStream(key));
      const float r = std::sqrt(rng.next()), v = rng.next();
      samples_.push_back({(1.0f - r) * a + r * (1.0f - v) * b + r * v * c, n / len, reflectance[t]});
      sampleKeys_.push_back(key);
    }
  }
}

std::size_t ReachedSurfaces::samplesOn(std::uint32_t first, std::uint32_t count) const {
  const auto lo = std::lower_bound(sampleKeys_.begin(), sampleKeys_.end(), std::uint64_t{first} << 32);
  const auto hi = std::lower_bound(sampleKeys_.begin(), sampleKeys_.end(), std::uint64_t{first + count} << 32);
  return static_cast<std::size_t>(hi - lo);
}

std::uint32_t ReachedSurfaces::sampleStream(std::uint64_t key) {
  std::uint64_t z = key * 0x9e3779b97f4a7c15ull; // a 32-bit stream index of its own for each (t, k)
  z = (z ^ (z >> 31)) * 0xbf58476d1ce4e5b9ull;
  return static_cast<std::uint32_t>(z ^ (z >> 29));
}

// What remeasure reuses: the measurement before the edit and the boxes the edit changed.
struct ReachedSurfaces::Replay {
  const ReachedSurfaces& before;
  const ReachRays& rays;
  const std::vector<std::pair<std::uint32_t, std::uint32_t>>& landedTriangles;
  const std::vector<scene::Bounds>& changed;
  std::vector<std::uint32_t> sampleBefore; // per surface sample: the same (t, k) before the edit, or kNone
  bool samplesInPlace;                     // sampleBefore[j] == j for every sample, and as many before
  static constexpr std::uint32_t kNone = ~0u;
  bool raysKept;          // `rays` holds the rays themselves (ReachRays::lightRay and the rest)

  bool meets(glm::vec3 origin, glm::vec3 direction, float tmax) const {
    for (const scene::Bounds& b : changed)
      if (segmentMeetsBox(origin, direction, tmax, b)) return true;
    return false;
  }
  bool overlaps(const scene::Bounds& box) const {
    for (const scene::Bounds& b : changed)
      if (!box.empty() && glm::all(glm::lessThanEqual(box.lo, b.hi)) && glm::all(glm::lessThanEqual(b.lo, box.hi))) return true;
    return false;
  }
};

LightReach ReachedSurfaces::measure(RayBatch& rays, const LightSet& lights, std::size_t light) const {
  return trace(rays, lights, light, nullptr);
}

LightReach ReachedSurfaces::measure(const LightSet& lights, std::size_t light) const {
  CpuRayBatch cpu(bvh());
  return measure(cpu, lights, light);
}

LightReach ReachedSurfaces::remeasure(RayBatch& batch, const ReachedSurfaces& before, const LightReach& previous,
                                      const LightSet& lights, std::size_t light,
                                      const std::vector<scene::Bounds>& changed) const {
  if (previous.rays.landingT.size() != kLightRays) return measure(batch, lights, light); // never measured
  // Ray origins leave their surfaces by a share of the scene's size: a move that changed it moved
  // every ray.
  if (before.offset_ != offset_) return measure(batch, lights, light);
  // The sky's and the sun's points are placed by the scene's bounds: a move that changed them
  // moved every one of those light points.
  const std::uint32_t type = lights.lights[light].info.x;
  const bool placedByBounds = type == gpu::kLightBackground || type == gpu::kLightDirectional;
  if (placedByBounds && (before.bounds_.lo != bounds_.lo || before.bounds_.hi != bounds_.hi))
    return measure(batch, lights, light);
  const ReachRays& kept = previous.rays;
  const bool raysKept = kept.lightRay.size() == kLightRays && kept.bounceDirection.size() == kLightRays &&
                        kept.landingTryDraws.size() == before.samples_.size() &&
                        kept.triedBounds.size() == before.samples_.size();
  Replay replay{before, previous.rays, previous.landedTriangles, changed, {}, false, raysKept};
  // The points matched by their keys (both sorted): an edit that added or moved triangles leaves
  // most where they were, under other indices after the first triangle whose count changed.
  replay.sampleBefore.assign(samples_.size(), Replay::kNone);
  for (std::size_t j = 0, i = 0; j < samples_.size(); ++j) {
    while (i < before.sampleKeys_.size() && before.sampleKeys_[i] < sampleKeys_[j]) ++i;
    if (i < before.sampleKeys_.size() && before.sampleKeys_[i] == sampleKeys_[j]) replay.sampleBefore[j] = static_cast<std::uint32_t>(i);
  }
  replay.samplesInPlace = before.samples_.size() == samples_.size();
  for (std::size_t j = 0; replay.samplesInPlace && j < samples_.size(); ++j) replay.samplesInPlace = replay.sampleBefore[j] == j;
  return trace(batch, lights, light, &replay);
}

LightReach ReachedSurfaces::remeasure(const ReachedSurfaces& before, const LightReach& previous, const LightSet& lights,
                                      std::size_t light, const std::vector<scene::Bounds>& changed) const {
  CpuRayBatch cpu(bvh());
  return remeasure(cpu, before, previous, lights, light, changed);
}

// The rays are traced a stage at a time (RayBatch): the light rays, their bounces, the surface
// samples' tries at the light, the tries at the landings of those still unseen, the Seen fit's
// shadow rays. Every ray draws from a stream of its own, so tracing a stage's rays together draws
// the numbers a ray-by-ray loop would: a sample's tries are all drawn (its stream goes on in
// order), and the first seen decides, as when the loop stopped there. Tries after the first seen
// are traced but not kept (tryBlockedAt stays NaN there, as before).
LightReach ReachedSurfaces::trace(RayBatch& batch, const LightSet& lights, std::size_t light, const Replay* replay) const {
  LightReach reach;
  if (samples_.empty() || !(lights.power[light] > 0.0)) return reach;
  const std::uint32_t seed = lightSeed(lights.names[light]);
  const scene::Scene& scene = *scene_;
  ReachRays& rays = reach.rays;
  auto offsetToward = [&](glm::vec3 p, glm::vec3 n, glm::vec3 towards) { return render::offsetToward(p, n, towards, offset_); };
  // A replay takes the rays from the measurement before where they are the same rays (the same
  // light, the same surface sample), instead of drawing them again.
  const bool keptRays = replay && replay->raysKept;
  // The rays of one stage: `ray[i]` belongs to `owner[i]`.
  struct Stage {
    std::vector<bvh::Ray> ray;
    std::vector<std::uint32_t> owner;
    void reserve(std::size_t n) {
      ray.reserve(n);
      owner.reserve(n);
    }
    void add(std::uint32_t who, const bvh::Ray& r) {
      ray.push_back(r);
      owner.push_back(who);
    }
  };

  // 1. Where the light lands: first hits of rays leaving it (the position and the lit side's
  // normal). A light ray is traced again when its segment up to its old hit meets a changed box:
  // every other ray has the same first hit in the edited scene.
  struct Landing : SurfacePoint { // where it landed, the lit side's normal, the reflectance there
    bool moved = false;            // re-traced: what was seen of it before says nothing now
  };
  std::vector<Landing> landingOf(kLightRays); // by light ray; valid where landingT is finite
  rays.landingT.assign(kLightRays, std::numeric_limits<float>::quiet_NaN());
  rays.landingPrimitive.assign(kLightRays, gpu::kInvalidIndex);
  std::vector<bvh::Ray>& lightRay = rays.lightRay;
  lightRay.assign(kLightRays, bvh::Ray{.origin = glm::vec3(0.0f), .direction = glm::vec3(0.0f)});
  std::vector<std::uint8_t> retraced(kLightRays, 0);
  std::uint32_t emitted = 0, landed = 0;
  {
    Stage stage;
    for (std::uint32_t i = 0; i < kLightRays; ++i) {
      bvh::Ray ray;
      if (keptRays) {
        if (std::isnan(replay->rays.landingT[i])) continue; // it emitted nothing before: nor now
        ray = replay->rays.lightRay[i];
      } else {
        StreamRng rng(seed, Stream::LightRay, i);
        LightPoint p = samplePoint(lights, light, rng, scene.bounds);
        glm::vec3 direction;
        if (!emitDirection(lights, light, p, rng, direction)) continue;
        ray = {.origin = p.normal == glm::vec3(0.0f) ? p.position : offsetToward(p.position, p.normal, p.position + direction),
               .direction = direction};
      }
      const glm::vec3 d = ray.direction;
      lightRay[i] = ray;
      ++emitted;
      const float t = replay ? replay->rays.landingT[i] : 0.0f;
      if (!replay || std::isnan(t) || replay->meets(ray.origin, d, t)) {
        stage.add(i, ray);
        retraced[i] = 1;
        rays.landingT[i] = kInfinity; // until traced
        continue;
      }
      rays.landingT[i] = t;
      rays.landingPrimitive[i] = replay->rays.landingPrimitive[i];
    }
    const std::vector<bvh::Hit> hits = batch.closest(stage.ray);
    rays.traced += stage.ray.size();
    for (std::size_t k = 0; k < hits.size(); ++k) {
      const std::uint32_t i = stage.owner[k];
      rays.landingT[i] = hits[k].hit() ? hits[k].t : kInfinity;
      rays.landingPrimitive[i] = hits[k].hit() ? hits[k].primitive : gpu::kInvalidIndex;
    }
  }
  std::vector<std::uint32_t> landedOn; // the triangle of every landing
  landedOn.reserve(kLightRays);
  for (std::uint32_t i = 0; i < kLightRays; ++i) {
    const float t = rays.landingT[i];
    if (!std::isfinite(t)) continue;
    const std::uint32_t primitive = rays.landingPrimitive[i];
    const glm::vec3 d = lightRay[i].direction;
    const glm::uvec3 tri = scene.triangles[primitive];
    glm::vec3 a = scene.positions[tri.x], b = scene.positions[tri.y], c = scene.positions[tri.z];
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    if (glm::dot(n, d) > 0.0f) n = -n; // the side the light arrives on
    landingOf[i] = {{lightRay[i].origin + t * d, n, reflectance_[primitive]}, retraced[i] != 0 && replay != nullptr};
    ++landed;
    landedOn.push_back(primitive);
  }
  const bool sameLandings = replay && std::find(retraced.begin(), retraced.end(), 1) == retraced.end();
  if (sameLandings) landedOn.clear(); // the same triangles as before
  reach.landedTriangles = sameLandings ? replay->landedTriangles : decltype(reach.landedTriangles){};
  std::sort(landedOn.begin(), landedOn.end()); // (triangle, rays) by triangle
  for (std::size_t i = 0; i < landedOn.size();) {
    std::size_t end = i;
    while (end < landedOn.size() && landedOn[end] == landedOn[i]) ++end;
    reach.landedTriangles.emplace_back(landedOn[i], static_cast<std::uint32_t>(end - i));
    i = end;
  }
  reach.landings = landed;

  // What leaves the scene: directly (not for a directional light, whose flux counts only what
  // crosses the scene's box already), and after one diffuse reflection where the light lands.
  const bool directional = lights.lights[light].info.x == gpu::kLightDirectional;
  reach.escapeDirect = directional || emitted == 0 ? 0.0 : 1.0 - static_cast<double>(landed) / emitted;
  rays.bounceBlockedAt.assign(kLightRays, kInfinity);
  rays.bounceDirection.assign(kLightRays, glm::vec3(0.0f));
  {
    Stage stage;
    for (std::uint32_t i = 0; i < kLightRays; ++i) {
      if (!std::isfinite(rays.landingT[i])) continue;
      const Landing& h = landingOf[i];
      glm::vec3 d;
      if (keptRays && !h.moved) {
        d = replay->rays.bounceDirection[i]; // the same landing: the same reflected ray
      } else {
        StreamRng rng(seed, Stream::Bounce, i);
        d = cosineDirection(h.normal, rng.next(), rng.next());
      }
      rays.bounceDirection[i] = d;
      bvh::Ray ray{.origin = h.position + offsetAt(h.position, offset_) * h.normal, .direction = d};
      // Blocked at t before: still blocked unless the segment up to there meets a changed box; left
      // the scene: still does unless the whole ray meets one.
      const float blockedAt = replay ? replay->rays.bounceBlockedAt[i] : kInfinity;
      if (!replay || h.moved || replay->meets(ray.origin, d, blockedAt)) stage.add(i, ray);
      else rays.bounceBlockedAt[i] = blockedAt;
    }
    const std::vector<float> blocked = batch.blockedAt(stage.ray);
    rays.traced += stage.ray.size();
    for (std::size_t k = 0; k < blocked.size(); ++k) rays.bounceBlockedAt[stage.owner[k]] = blocked[k];
  }
  std::size_t escapedBounce = 0;
  for (std::uint32_t i = 0; i < kLightRays; ++i)
    if (std::isfinite(rays.landingT[i]) && std::isinf(rays.bounceBlockedAt[i])) ++escapedBounce;
  reach.escapeBounce = landed == 0 ? 0.0 : static_cast<double>(escapedBounce) / static_cast<double>(landed);

  // 2. Surface samples that see the light or a landing point: up to kVisibilityTries points of the
  // light, then as many landing points (a light ray picked at random; none when it did not land),
  // the first seen deciding. Before an edit, try k of sample j was unseen for k < its first seen
  // try, seen at it, and not traced after it.
  // A try's outcome: known from before the edit, or found by its ray.
  enum class Outcome : std::uint8_t { Skipped, Seen, Blocked, Traced };
  struct Try {
    Outcome outcome = Outcome::Skipped;
    float blockedAt = kNaN; // Blocked: where
    std::uint32_t ray = 0;  // Traced: its index in the stage
  };
  std::vector<std::uint8_t> same(samples_.size(), 0); // sample j is where it was before the edit
  if (replay)
    for (std::size_t j = 0; j < samples_.size(); ++j) {
      const std::uint32_t i = replay->sampleBefore[j];
      same[j] = i != Replay::kNone && replay->before.samples_[i] == samples_[j];
    }
  auto sameSample = [&](std::size_t j) { return same[j] != 0; };
  auto was = [&](std::size_t j) { return replay->sampleBefore[j]; }; // its index before (sameSample)
  // A sample of the replay whose tries all find what they found before: the box around their
  // segments meets no changed box, and no landing one of them aimed at was re-traced (so moved).
  // Its outcome is copied whole, the tries not looked at one by one (most samples of a move).
  std::vector<std::uint8_t> kept(samples_.size(), 0);
  auto keepsItsTries = [&](std::size_t j) {
    if (replay->overlaps(replay->rays.triedBounds[was(j)])) return false;
    const std::uint8_t first = replay->rays.firstSeenTry[was(j)];
    if (first != kNotSeen && first < kVisibilityTries) return true; // no landing tried
    StreamRng draws = StreamRng::resumed(replay->rays.landingTryDraws[was(j)]);
    for (std::uint32_t landingTry = 0; landingTry < kVisibilityTries; ++landingTry)
      if (retraced[draws.below(kLightRays)]) return false;
    return true;
  };
  // The tries of the samples not kept, kTries each from triesOf[j].
  std::vector<std::uint32_t> triesOf(samples_.size(), 0);
  std::vector<std::uint32_t> lookedAt; // the samples not kept, in order
  for (std::size_t j = 0; j < samples_.size(); ++j) {
    kept[j] = keptRays && sameSample(j) && keepsItsTries(j);
    if (kept[j]) continue;
    triesOf[j] = static_cast<std::uint32_t>(kTries * lookedAt.size());
    lookedAt.push_back(static_cast<std::uint32_t>(j));
  }
  const std::size_t looked = lookedAt.size();
  std::vector<Try> tries(kTries * looked);
  // Try k of sample j, the segment from -> to: seen before and its whole segment clear of the
  // changed boxes, or blocked at t before and its segment up to t clear of them, it finds the
  // same now; otherwise its ray goes into the stage.
  // decided[j]: a try of sample j is known seen, so its later tries cannot matter (not planned).
  std::vector<std::uint8_t> decided(samples_.size(), 0);
  // A try found as before goes into the sample's triedBounds now (should an earlier try turn out
  // seen, the box is only larger than it need be); a traced one when it is decided.
  auto plan = [&](Stage& stage, std::size_t j, std::uint32_t k, glm::vec3 from, glm::vec3 to, bool targetMoved) {
    Try& tr = tries[triesOf[j] + k];
    if (decided[j]) return;
    if (sameSample(j) && !targetMoved) {
      const float before = replay->rays.tryBlockedAt[was(j) * kTries + k];
      if (k == replay->rays.firstSeenTry[was(j)] && !replay->meets(from, to - from, 1.0f)) {
        tr = {Outcome::Seen, kNaN, 0};
        rays.triedBounds[j].grow(from);
        rays.triedBounds[j].grow(to);
        decided[j] = 1;
        return;
      }
      if (!std::isnan(before) && !replay->meets(from, to - from, before)) {
        tr = {Outcome::Blocked, before, 0};
        rays.triedBounds[j].grow(from);
        rays.triedBounds[j].grow(from + before * (to - from));
        return;
      }
    }
    tr = {Outcome::Traced, kNaN, static_cast<std::uint32_t>(stage.ray.size())};
    stage.add(static_cast<std::uint32_t>(j), {.origin = from, .direction = to - from, .tmin = 0.0f, .tmax = 1.0f});
  };
  // Walks tries [first, last) of sample j in order with their stage's results: the first seen
  // decides; the blocked ones before it keep where they were blocked.
  auto decide = [&](std::size_t j, std::uint32_t first, std::uint32_t last, const Stage& stage,
                    const std::vector<float>& blocked) {
    scene::Bounds& box = rays.triedBounds[j];
    for (std::uint32_t k = first; k < last; ++k) {
      const Try& tr = tries[triesOf[j] + k];
      float at = tr.blockedAt;
      if (tr.outcome == Outcome::Skipped) continue;
      const bool traced = tr.outcome == Outcome::Traced;
      if (traced) at = blocked[tr.ray];
      const bool seen = tr.outcome == Outcome::Seen || std::isinf(at);
      if (traced) { // its segment, up to where it was blocked
        const bvh::Ray& ray = stage.ray[tr.ray];
        box.grow(ray.origin);
        box.grow(ray.origin + (seen ? 1.0f : at) * ray.direction);
      }
      if (seen) {
        rays.firstSeenTry[j] = static_cast<std::uint8_t>(k);
        return true;
      }
      rays.tryBlockedAt[j * kTries + k] = at;
    }
    return false;
  };
  {
    Stage stage; // the tries at points of the light
    stage.reserve(kVisibilityTries * looked);
    if (looked < samples_.size() && replay->samplesInPlace) {
      // Most samples kept, where they were: their outcomes copied whole, the others' cleared below.
      rays.firstSeenTry = replay->rays.firstSeenTry;
      rays.tryBlockedAt = replay->rays.tryBlockedAt;
      rays.triedBounds = replay->rays.triedBounds;
      rays.landingTryDraws = replay->rays.landingTryDraws;
    } else {
      rays.firstSeenTry.assign(samples_.size(), kNotSeen);
      rays.tryBlockedAt.assign(samples_.size() * kTries, kNaN);
      rays.triedBounds.assign(samples_.size(), scene::Bounds{});
      rays.landingTryDraws.resize(samples_.size());
      if (looked < samples_.size()) // kept under other indices
        for (std::size_t j = 0; j < samples_.size(); ++j) {
          if (!kept[j]) continue;
          rays.firstSeenTry[j] = replay->rays.firstSeenTry[was(j)];
          std::copy_n(&replay->rays.tryBlockedAt[was(j) * kTries], kTries, &rays.tryBlockedAt[j * kTries]);
          rays.triedBounds[j] = replay->rays.triedBounds[was(j)];
          rays.landingTryDraws[j] = replay->rays.landingTryDraws[was(j)];
        }
    }
    for (const std::uint32_t j : lookedAt) { // the others are found as before, try by try
      rays.firstSeenTry[j] = kNotSeen;
      std::fill_n(&rays.tryBlockedAt[j * kTries], kTries, kNaN);
      rays.triedBounds[j] = {};
      // The points on the light drawn again (a few per sample that is not kept).
      const SurfacePoint& s = samples_[j];
      StreamRng rng(seed, Stream::Sample, sampleStream(sampleKeys_[j]));
      for (std::uint32_t k = 0; k < kVisibilityTries; ++k) {
        const glm::vec3 target = lightTryTarget(lights, light, s, rng);
        if (!std::isnan(target.x)) plan(stage, j, k, offsetToward(s.position, s.normal, target), target, false);
      }
      rays.landingTryDraws[j] = rng.state();
    }
    const std::vector<float> blocked = batch.blockedAt(stage.ray);
    rays.traced += stage.ray.size();
    for (const std::uint32_t j : lookedAt) decide(j, 0, kVisibilityTries, stage, blocked);
  }
  if (landed > 0) {
    Stage stage; // the tries at landing points, for the samples the light itself did not see
    stage.reserve(kVisibilityTries * looked);
    for (const std::uint32_t j : lookedAt) {
      if (rays.firstSeenTry[j] != kNotSeen) continue;
      const SurfacePoint& s = samples_[j];
      StreamRng draws = StreamRng::resumed(rays.landingTryDraws[j]);
      for (std::uint32_t landingTry = 0; landingTry < kVisibilityTries; ++landingTry) {
        const std::uint32_t k = kVisibilityTries + landingTry;
        const std::uint32_t i = draws.below(kLightRays);
        if (!std::isfinite(rays.landingT[i])) continue; // that light ray left the scene
        const Landing& h = landingOf[i];
        if (glm::dot(h.normal, s.position - h.position) <= 0.0f) continue; // behind the lit side
        glm::vec3 target = h.position + offsetAt(h.position, offset_) * h.normal;
        plan(stage, j, k, offsetToward(s.position, s.normal, target), target, h.moved);
      }
    }
    const std::vector<float> blocked = batch.blockedAt(stage.ray);
    rays.traced += stage.ray.size();
    for (const std::uint32_t j : lookedAt)
      if (rays.firstSeenTry[j] == kNotSeen) decide(j, kVisibilityTries, kTries, stage, blocked);
  }
  std::size_t reached = 0;
  glm::dvec3 reflectance(0.0);
  for (std::size_t j = 0; j < samples_.size(); ++j) {
    if (rays.firstSeenTry[j] == kNotSeen) continue;
    ++reached;
    reflectance += glm::dvec3(samples_[j].reflectance);
  }
  if (reached == 0) return reach;
  reach.fraction = static_cast<double>(reached) / static_cast<double>(samples_.size());
  reach.area = totalArea_ * reach.fraction;
  reach.reflectance = glm::vec3(reflectance / static_cast<double>(reached));

  // 3. Seen: the one-bounce irradiance at the camera's points. Measured whole after an edit too
  // (its rays are a few per seen point): it reads only the landings and the seen points, so a
  // replayed measurement fits what a fresh one fits.
  const std::uint32_t type = lights.lights[light].info.x;
  if (!seen_.empty() && glm::length(seenModel_) > 0.0) {
    std::optional<glm::dvec3> target;
    if (type == gpu::kLightDirectional || type == gpu::kLightBackground) {
      target = gatheredFirstBounce(batch, lights, light, seed, rays.traced);
    } else {
      std::vector<SurfacePoint> landings;
      for (std::uint32_t i = 0; i < kLightRays; ++i)
        if (std::isfinite(rays.landingT[i])) landings.push_back(landingOf[i]);
      if (!landings.empty()) {
        const glm::dvec3 flux = glm::dvec3(lights.unitFlux[light]) * (1.0 - reach.escapeDirect) / static_cast<double>(landings.size());
        const double rc2 = reach.area / (std::numbers::pi * static_cast<double>(landings.size()));
        target = landingsFirstBounce(batch, landings, flux, rc2, seed, rays.traced);
      }
    }
    if (target) {
      for (int c = 0; c < 3; ++c)
        reach.seenFirstBounce[c] = seenModel_[c] > 0.0 ? static_cast<float>((*target)[c] / seenModel_[c]) : 0.0f;
      reach.seenBounce = seenBounce_;
      reach.seenFitted = true;
    }
  }
  return reach;
}

glm::vec3 ReachedSurfaces::lightTryTarget(const LightSet& lights, std::size_t light, const SurfacePoint& sample,
                                          StreamRng& rng) const {
  const gpu::GpuLight& l = lights.lights[light];
  const LightPoint p = samplePoint(lights, light, rng, scene_->bounds);
  if (p.directional) return sample.position - 4.0f * largestExtent(scene_->bounds) * p.direction; // towards the sun
  if (p.normal != glm::vec3(0.0f) && !p.twoSided && glm::dot(p.normal, sample.position - p.position) <= 0.0f) return glm::vec3(kNaN);
  if (l.info.x == gpu::kLightSpot && glm::dot(glm::normalize(sample.position - p.position), glm::vec3(l.direction)) < l.params.w)
    return glm::vec3(kNaN);
  return p.normal == glm::vec3(0.0f) ? p.position : offsetToward(p.position, p.normal, sample.position, offset_);
}

// A light inside the scene: its landings as virtual point lights ("photons"), each carrying its
// flux Phi_i and reflecting R cos / pi per steradian, so
//   E_1(P) = sum_i Phi_i R_i cos_i cos_P / (pi max(r^2, r_c,i^2)) V(i, P),
// estimated from kSeenLandingsPerPoint random photons. r_c (rc2 = r_c^2), the radius of a
// photon's share of the lit area, bounds the 1/r^2 of a landing next to P (that light is the
// direct light's neighbourhood, which the ambient term never resolves anyway).
glm::dvec3 ReachedSurfaces::landingsFirstBounce(RayBatch& batch, const std::vector<SurfacePoint>& landings, glm::dvec3 flux,
                                                double rc2, std::uint32_t seed, std::uint64_t& traced) const {
  StreamRng rng(seed, Stream::Seen, 0);
  // Every point's photon draws first (they do not depend on what the rays find), then their
  // shadow rays at once, then the sums in the same order.
  struct Gather {
    std::uint32_t point;
    glm::dvec3 contribution; // if visible
  };
  std::vector<Gather> gathers;
  std::vector<bvh::Ray> shadow;
  for (std::uint32_t point = 0; point < seen_.size(); ++point) {
    const SurfacePoint& p = seen_[point];
    for (std::uint32_t k = 0; k < kSeenLandingsPerPoint; ++k) {
      const SurfacePoint& h = landings[rng.below(static_cast<std::uint32_t>(landings.size()))];
      glm::vec3 d = h.position - p.position;
      const float r2 = glm::dot(d, d);
      if (!(r2 > 0.0f)) continue;
      d /= std::sqrt(r2);
      const float cosP = glm::dot(p.normal, d), cosL = -glm::dot(h.normal, d);
      if (cosP <= 0.0f || cosL <= 0.0f) continue;
      glm::vec3 from = p.position + offsetAt(p.position, offset_) * p.normal;
      glm::vec3 to = h.position + offsetAt(h.position, offset_) * h.normal;
      shadow.push_back({.origin = from, .direction = to - from, .tmin = 0.0f, .tmax = 1.0f});
      gathers.push_back({point, flux * glm::dvec3(h.reflectance) * static_cast<double>(cosP * cosL) /
                                    std::max(static_cast<double>(r2), rc2)});
    }
  }
  const std::vector<float> blocked = batch.blockedAt(shadow);
  traced += shadow.size();
  std::vector<glm::dvec3> sum(seen_.size(), glm::dvec3(0.0));
  for (std::size_t g = 0; g < gathers.size(); ++g)
    if (std::isinf(blocked[g])) sum[gathers[g].point] += gathers[g].contribution;
  glm::dvec3 target(0.0);
  for (std::uint32_t point = 0; point < seen_.size(); ++point) {
    // Landings drawn uniformly: the sum over all of them is landings / K times this one.
    const glm::dvec3 e1 = sum[point] * (static_cast<double>(landings.size()) / kSeenLandingsPerPoint) / std::numbers::pi;
    target += glm::dvec3(seen_[point].reflectance) * e1 / std::numbers::pi;
  }
  return target;
}

// The sun and the sky light the seen points' room from outside the scene: of their rays, spread
// over the whole world, few land where the camera looks (classroom: a room in a 221 m world, lit
// through its windows), and which few decided the fit (it swung 0.9-1.2x with the streams). So
// their first bounce is gathered instead, from where the seen points' cosine rays landed (Q, kept
// by setSeenView): E_1(P) = (1/K) sum_k R(Q_k) E_dir(Q_k) for K cosine rays (L_1 = R E_dir / pi,
// E = pi x the mean radiance), and E_dir(Q) at unit emission takes one shadow ray: the sun's
// irradiance 1 across its direction, cos x V; the sky's radiance 1, pi x V of a cosine ray.
// Every sunlit or skylit surface the room sees counts, wherever it is, with no 1/r^2 to clamp.
glm::dvec3 ReachedSurfaces::gatheredFirstBounce(RayBatch& batch, const LightSet& lights, std::size_t light,
                                                std::uint32_t seed, std::uint64_t& traced) const {
  const bool sky = lights.lights[light].info.x == gpu::kLightBackground;
  const glm::vec3 sunTravels = glm::normalize(glm::vec3(lights.lights[light].direction));
  std::vector<bvh::Ray> shadow;
  std::vector<double> cosine;     // E_dir(Q) if the shadow ray is clear
  std::vector<std::uint32_t> gather; // its seenGathers_ index
  for (std::uint32_t i = 0; i < seenGathers_.size(); ++i) {
    const SeenGather& q = seenGathers_[i];
    glm::vec3 towards;
    double e = 0.0;
    if (sky) {
      StreamRng rng(seed, Stream::SeenGather, i);
      const float u1 = rng.next(), u2 = rng.next();
      towards = cosineDirection(q.normal, u1, u2);
      e = std::numbers::pi;
    } else {
      towards = -sunTravels;
      e = glm::dot(q.normal, towards);
      if (!(e > 0.0)) continue;
    }
    shadow.push_back({.origin = q.position, .direction = towards});
    cosine.push_back(e);
    gather.push_back(i);
  }
  const std::vector<float> blocked = batch.blockedAt(shadow);
  traced += shadow.size();
  glm::dvec3 target(0.0);
  for (std::size_t r = 0; r < shadow.size(); ++r)
    if (std::isinf(blocked[r])) target += seenGathers_[gather[r]].weight * cosine[r];
  return target;
}

void ReachedSurfaces::setSeenView(const SeenView& view) {
  CpuRayBatch cpu(bvh());
  setSeenView(cpu, view);
}

// The camera's points (a jittered grid), then at each W_c (or W) as obscurance.glsl estimates it
// (cosine rays of length dmax, or unbounded with dark escapes: one that leaves the scene adds
// nothing) and what comes back at all (any distance: the later bounces' q).
// Each cell draws from a stream of its own, so that a stage's rays are traced together.
void ReachedSurfaces::setSeenView(RayBatch& batch, const SeenView& view) {
  seen_.clear();
  seenGathers_.clear();
  seenModel_ = glm::dvec3(0.0);
  const scene::Scene& scene = *scene_;
  const GridCamera camera{view.position, view.forward, view.up, view.yfov, view.aspect};
  constexpr std::uint32_t kSeenSeed = 0x5ee9u;
  constexpr std::uint32_t kCells = kSeenGrid * kSeenGrid;
  std::vector<bvh::Ray> cameraRays;
  std::vector<StreamRng> cellRng;
  cellRng.reserve(kCells);
  for (std::uint32_t cell = 0; cell < kCells; ++cell) {
    StreamRng& rng = cellRng.emplace_back(kSeenSeed, Stream::SeenGrid, cell);
    const float gx = static_cast<float>(cell % kSeenGrid) + rng.next();
    const float gy = static_cast<float>(cell / kSeenGrid) + rng.next();
    cameraRays.push_back(gridRay(camera, gx, gy, static_cast<int>(kSeenGrid)));
  }
  const std::vector<bvh::Hit> cameraHits = batch.closest(cameraRays);
  std::vector<SurfacePoint> points;
  std::vector<bvh::Ray> bounceRays, obscuranceRays; // kSeenObscuranceRays of each per point
  for (std::uint32_t cell = 0; cell < kCells; ++cell) {
    const auto hit = gridHit(scene, cameraRays[cell], cameraHits[cell]);
    if (!hit) continue;
    const glm::vec3 n = hit->normal;
    points.push_back({hit->position, n, reflectance_[hit->primitive]});
    const glm::vec3 origin = hit->position + offsetAt(hit->position, offset_) * n;
    StreamRng& rng = cellRng[cell];
    for (std::uint32_t k = 0; k < kSeenObscuranceRays; ++k) {
      const float u1 = rng.next(), u2 = rng.next();
      bounceRays.push_back({.origin = origin, .direction = cosineDirection(n, u1, u2)});
      const float v1 = rng.next(), v2 = rng.next();
      obscuranceRays.push_back({.origin = origin, .direction = cosineDirection(n, v1, v2), .tmin = 0.0f,
                                .tmax = view.darkEscapes ? std::numeric_limits<float>::infinity() : view.dMax});
    }
  }
  const std::vector<bvh::Hit> bounceHits = batch.closest(bounceRays);
  const std::vector<bvh::Hit> obscuranceHits = batch.closest(obscuranceRays);
  glm::dvec3 bounce(0.0);
  for (std::size_t r = 0; r < bounceRays.size(); ++r) {
    const bvh::Hit& any = bounceHits[r];
    if (!any.hit()) continue;
    bounce += glm::dvec3(reflectance_[any.primitive]);
    // Where it landed, for gatheredFirstBounce: its share of sum_P R(P) E_1(P) / pi per unit of
    // the direct irradiance there is R(P) R(Q) / (K pi).
    const auto q = gridHit(scene, bounceRays[r], any);
    const glm::dvec3 weight = glm::dvec3(points[r / kSeenObscuranceRays].reflectance) * glm::dvec3(reflectance_[any.primitive]) /
                              (kSeenObscuranceRays * std::numbers::pi);
    if (!q || !(weight.x + weight.y + weight.z > 0.0)) continue;
    seenGathers_.push_back({q->position + offsetAt(q->position, offset_) * q->normal, q->normal, weight});
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SurfacePoint& p = points[i];
    glm::dvec3 w(0.0);
    for (std::uint32_t k = 0; k < kSeenObscuranceRays; ++k) {
      const bvh::Hit& q = obscuranceHits[i * kSeenObscuranceRays + k];
      glm::vec3 r = view.colourBleeding ? view.averageReflectance : glm::vec3(1.0f);
      float rho = 1.0f;
      if (q.hit() && q.t < view.dMax) {
        rho = obscuranceRho(q.t, view.dMax, view.rho, view.tau);
        r = view.colourBleeding ? reflectance_[q.primitive] : glm::vec3(1.0f);
      } else if (!q.hit() && view.darkEscapes) {
        r = glm::vec3(0.0f); // it left the scene (the closest hit past dmax stands for the shader's any-hit)
      }
      w += glm::dvec3(r) * static_cast<double>(rho);
    }
    seenModel_ += glm::dvec3(p.reflectance) * w / static_cast<double>(kSeenObscuranceRays);
    seen_.push_back(p);
  }
  seenBounce_ = bounceRays.empty() ? glm::vec3(0.0f) : glm::vec3(bounce / static_cast<double>(bounceRays.size()));
}

} // namespace obscura::render

