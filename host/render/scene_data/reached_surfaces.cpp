#include "render/scene_data/reached_surfaces.h"

#include "render/scene_data/camera_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <limits>
#include <random>
#include <string>

namespace obscura::render {

// The streams of a light's measurement: one per ray (or per surface sample, whose tries share it).
enum class Stream : std::uint32_t { LightRay = 1, Bounce = 2, Sample = 3, Seen = 4 };

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

private:
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
    std::uint32_t first = l.info.y, count = l.info.z, e = first;
    while (e + 1 < first + count && lights.emitters[e].v0.w <= u) ++e;
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

// Whether the segment origin + t direction, t in [0, tmax] (tmax may be infinite), meets the box:
// the slab test, an axis the direction runs parallel to tested on the origin alone.
bool segmentMeetsBox(glm::vec3 origin, glm::vec3 direction, float tmax, const scene::Bounds& box) {
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

ReachedSurfaces::ReachedSurfaces(const scene::Scene& scene, const bvh::Bvh& bvh, const std::vector<glm::vec3>& reflectance)
    : scene_(&scene), bvh_(bvh), reflectance_(reflectance), bounds_(scene.bounds),
      offset_(1e-5f * largestExtent(scene.bounds)) {
  std::vector<double> cdf;
  cdf.reserve(scene.triangles.size());
  for (const auto& t : scene.triangles) {
    glm::dvec3 a(scene.positions[t.x]), b(scene.positions[t.y]), c(scene.positions[t.z]);
    totalArea_ += 0.5 * glm::length(glm::cross(b - a, c - a));
    cdf.push_back(totalArea_);
  }
  if (!(totalArea_ > 0.0)) return;
  std::mt19937 rng(0x5eed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (std::uint32_t i = 0; i < kSurfaceSamples; ++i) {
    auto it = std::upper_bound(cdf.begin(), cdf.end(), uni(rng) * totalArea_);
    std::size_t t = std::min<std::size_t>(static_cast<std::size_t>(it - cdf.begin()), cdf.size() - 1);
    const glm::uvec3 tri = scene.triangles[t];
    glm::vec3 a = scene.positions[tri.x], b = scene.positions[tri.y], c = scene.positions[tri.z];
    float r = static_cast<float>(std::sqrt(uni(rng))), v = static_cast<float>(uni(rng));
    glm::vec3 n = glm::cross(b - a, c - a);
    float len = glm::length(n);
    if (!(len > 0.0f)) continue;
    samples_.push_back({(1.0f - r) * a + r * (1.0f - v) * b + r * v * c, n / len, reflectance[t]});
  }
}

// What remeasure reuses: the measurement before the edit and the boxes the edit changed.
struct ReachedSurfaces::Replay {
  const ReachedSurfaces& before;
  const ReachRays& rays;
  const std::vector<scene::Bounds>& changed;
  bool samplesComparable; // the same number of surface samples: sample j before is sample j now

  bool meets(glm::vec3 origin, glm::vec3 direction, float tmax) const {
    for (const scene::Bounds& b : changed)
      if (segmentMeetsBox(origin, direction, tmax, b)) return true;
    return false;
  }
};

LightReach ReachedSurfaces::measure(const LightSet& lights, std::size_t light) const {
  return trace(lights, light, nullptr);
}

LightReach ReachedSurfaces::remeasure(const ReachedSurfaces& before, const LightReach& previous, const LightSet& lights,
                                      std::size_t light, const std::vector<scene::Bounds>& changed) const {
  if (previous.rays.landingT.size() != kLightRays) return measure(lights, light); // never measured
  // Ray origins leave their surfaces by a share of the scene's size: a move that changed it moved
  // every ray.
  if (before.offset_ != offset_) return measure(lights, light);
  // The sky's and the sun's points are placed by the scene's bounds: a move that changed them
  // moved every one of those light points.
  const std::uint32_t type = lights.lights[light].info.x;
  const bool placedByBounds = type == gpu::kLightBackground || type == gpu::kLightDirectional;
  if (placedByBounds && (before.bounds_.lo != bounds_.lo || before.bounds_.hi != bounds_.hi)) return measure(lights, light);
  const Replay replay{before, previous.rays, changed, before.samples_.size() == samples_.size()};
  return trace(lights, light, &replay);
}

LightReach ReachedSurfaces::trace(const LightSet& lights, std::size_t light, const Replay* replay) const {
  LightReach reach;
  if (samples_.empty() || !(lights.power[light] > 0.0)) return reach;
  const std::uint32_t seed = lightSeed(lights.names[light]);
  const scene::Scene& scene = *scene_;
  ReachRays& rays = reach.rays;
  auto offsetToward = [&](glm::vec3 p, glm::vec3 n, glm::vec3 towards) {
    const float o = offsetAt(p, offset_);
    return p + (glm::dot(n, towards - p) >= 0.0f ? o : -o) * n;
  };

  // 1. Where the light lands: first hits of rays leaving it (the position and the lit side's
  // normal). A light ray is traced again when its segment up to its old hit meets a changed box:
  // every other ray has the same first hit in the edited scene.
  struct Landing {
    glm::vec3 position, normal, reflectance;
    glm::vec3 from, direction; // the light ray that landed there
    bool moved = false;        // re-traced: what was seen of it before says nothing now
  };
  std::vector<Landing> landingOf(kLightRays); // by light ray; valid where landingT is finite
  rays.landingT.assign(kLightRays, std::numeric_limits<float>::quiet_NaN());
  rays.landingPrimitive.assign(kLightRays, gpu::kInvalidIndex);
  std::map<std::uint32_t, std::uint32_t> landedOn; // triangle -> rays
  std::uint32_t emitted = 0, landed = 0;
  for (std::uint32_t i = 0; i < kLightRays; ++i) {
    StreamRng rng(seed, Stream::LightRay, i);
    LightPoint p = samplePoint(lights, light, rng, scene.bounds);
    glm::vec3 d;
    if (!emitDirection(lights, light, p, rng, d)) continue;
    bvh::Ray ray{.origin = p.normal == glm::vec3(0.0f) ? p.position : offsetToward(p.position, p.normal, p.position + d),
                 .direction = d};
    ++emitted;
    float t = replay ? replay->rays.landingT[i] : 0.0f;
    std::uint32_t primitive = replay ? replay->rays.landingPrimitive[i] : gpu::kInvalidIndex;
    const bool retrace = !replay || std::isnan(t) || replay->meets(ray.origin, d, t);
    if (retrace) {
      bvh::Hit hit = bvh::closestHit(bvh_, ray);
      ++rays.traced;
      t = hit.hit() ? hit.t : std::numeric_limits<float>::infinity();
      primitive = hit.hit() ? hit.primitive : gpu::kInvalidIndex;
    }
    rays.landingT[i] = t;
    rays.landingPrimitive[i] = primitive;
    if (!std::isfinite(t)) continue;
    const glm::uvec3 tri = scene.triangles[primitive];
    glm::vec3 a = scene.positions[tri.x], b = scene.positions[tri.y], c = scene.positions[tri.z];
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    if (glm::dot(n, d) > 0.0f) n = -n; // the side the light arrives on
    landingOf[i] = {ray.origin + t * d, n, reflectance_[primitive], ray.origin, d, retrace && replay};
    ++landed;
    ++landedOn[primitive];
  }
  reach.landedTriangles.assign(landedOn.begin(), landedOn.end());
  reach.landings = landed;

  // What leaves the scene: directly (not for a directional light, whose flux counts only what
  // crosses the scene's box already), and after one diffuse reflection where the light lands.
  const bool directional = lights.lights[light].info.x == gpu::kLightDirectional;
  reach.escapeDirect = directional || emitted == 0 ? 0.0 : 1.0 - static_cast<double>(landed) / emitted;
  std::size_t escapedBounce = 0;
  rays.bounceBlockedAt.assign(kLightRays, kInfinity);
  for (std::uint32_t i = 0; i < kLightRays; ++i) {
    if (!std::isfinite(rays.landingT[i])) continue;
    const Landing& h = landingOf[i];
    StreamRng rng(seed, Stream::Bounce, i);
    glm::vec3 d = cosineDirection(h.normal, rng.next(), rng.next());
    bvh::Ray ray{.origin = h.position + offsetAt(h.position, offset_) * h.normal, .direction = d};
    // Blocked at t before: still blocked unless the segment up to there meets a changed box; left
    // the scene: still does unless the whole ray meets one.
    float blockedAt = replay ? replay->rays.bounceBlockedAt[i] : kInfinity;
    if (!replay || h.moved || replay->meets(ray.origin, d, blockedAt)) {
      blockedAt = kInfinity;
      bvh::anyHit(bvh_, ray, &blockedAt);
      ++rays.traced;
    }
    rays.bounceBlockedAt[i] = blockedAt;
    escapedBounce += std::isinf(blockedAt) ? 1 : 0;
  }
  reach.escapeBounce = landed == 0 ? 0.0 : static_cast<double>(escapedBounce) / static_cast<double>(landed);

  // 2. Surface samples that see the light or a landing point: up to kVisibilityTries points of the
  // light, then as many landing points (a light ray picked at random; none when it did not land),
  // stopping at the first seen. Before an edit, try k of sample j was unseen for k < its first seen
  // try, seen at it, and not traced after it.
  const gpu::GpuLight& l = lights.lights[light];
  std::size_t reached = 0;
  glm::dvec3 reflectance(0.0);
  rays.firstSeenTry.assign(samples_.size(), kNotSeen);
  rays.tryBlockedAt.assign(samples_.size() * kTries, kNaN);
  for (std::size_t j = 0; j < samples_.size(); ++j) {
    const SurfacePoint& s = samples_[j];
    const bool sameSample = replay && replay->samplesComparable && replay->before.samples_[j] == s;
    const std::uint8_t firstBefore = sameSample ? replay->rays.firstSeenTry[j] : kNotSeen;
    // Try k, the segment from -> to: seen before and its whole segment clear of the changed boxes,
    // or blocked at t before and its segment up to t clear of them, it finds the same now.
    auto seenFrom = [&](std::uint32_t k, glm::vec3 from, glm::vec3 to, bool targetMoved) {
      float& blockedAt = rays.tryBlockedAt[j * kTries + k];
      if (sameSample && !targetMoved) {
        const float before = replay->rays.tryBlockedAt[j * kTries + k];
        if (k == firstBefore && !replay->meets(from, to - from, 1.0f)) return true;
        if (!std::isnan(before) && !replay->meets(from, to - from, before)) {
          blockedAt = before;
          return false;
        }
      }
      bvh::Ray ray{.origin = from, .direction = to - from, .tmin = 0.0f, .tmax = 1.0f};
      ++rays.traced;
      float t = kNaN;
      if (!bvh::anyHit(bvh_, ray, &t)) return true;
      blockedAt = t;
      return false;
    };
    StreamRng rng(seed, Stream::Sample, static_cast<std::uint32_t>(j));
    bool seen = false;
    std::uint32_t k = 0;
    for (; k < kVisibilityTries && !seen; ++k) {
      LightPoint p = samplePoint(lights, light, rng, scene.bounds);
      if (p.directional) {
        glm::vec3 to = s.position - 4.0f * largestExtent(scene.bounds) * p.direction;
        seen = seenFrom(k, offsetToward(s.position, s.normal, to), to, false);
        continue;
      }
      if (p.normal != glm::vec3(0.0f) && !p.twoSided && glm::dot(p.normal, s.position - p.position) <= 0.0f) continue;
      if (l.info.x == gpu::kLightSpot && glm::dot(glm::normalize(s.position - p.position), glm::vec3(l.direction)) < l.params.w)
        continue;
      glm::vec3 target = p.normal == glm::vec3(0.0f) ? p.position : offsetToward(p.position, p.normal, s.position);
      seen = seenFrom(k, offsetToward(s.position, s.normal, target), target, false);
    }
    for (std::uint32_t tries = 0; tries < kVisibilityTries && !seen && landed > 0; ++tries) {
      const std::uint32_t k2 = kVisibilityTries + tries;
      const std::uint32_t i = rng.below(kLightRays);
      if (!std::isfinite(rays.landingT[i])) continue; // that light ray left the scene
      const Landing& h = landingOf[i];
      if (glm::dot(h.normal, s.position - h.position) <= 0.0f) continue; // behind the lit side
      glm::vec3 target = h.position + offsetAt(h.position, offset_) * h.normal;
      seen = seenFrom(k2, offsetToward(s.position, s.normal, target), target, h.moved);
      if (seen) k = k2 + 1;
    }
    if (seen) {
      rays.firstSeenTry[j] = static_cast<std::uint8_t>(k - 1);
      ++reached;
      reflectance += glm::dvec3(s.reflectance);
    }
  }
  if (reached == 0) return reach;
  reach.fraction = static_cast<double>(reached) / static_cast<double>(samples_.size());
  reach.area = totalArea_ * reach.fraction;
  reach.reflectance = glm::vec3(reflectance / static_cast<double>(reached));

  // 3. Seen: the one-bounce irradiance at the camera's points, the landings as virtual point
  // lights ("photons"): each carries its flux Phi_i and reflects R cos / pi per steradian, so
  //   E_1(P) = sum_i Phi_i R_i cos_i cos_P / (pi max(r^2, r_c,i^2)) V(i, P),
  // estimated from kSeenLandingsPerPoint random photons. r_c,i, the radius of photon i's share of
  // the lit area, bounds the 1/r^2 of a landing next to P (that light is the direct light's
  // neighbourhood, which the ambient term never resolves anyway).
  // Measured whole after an edit too (its rays are a few per seen point): it reads only the
  // landings, so a replayed measurement fits what a fresh one fits.
  std::vector<Landing> landings;
  for (std::uint32_t i = 0; i < kLightRays; ++i)
    if (std::isfinite(rays.landingT[i])) landings.push_back(landingOf[i]);
  StreamRng rng(seed, Stream::Seen, 0);
  auto visible = [&](glm::vec3 from, glm::vec3 to) {
    bvh::Ray ray{.origin = from, .direction = to - from, .tmin = 0.0f, .tmax = 1.0f};
    ++rays.traced;
    return !bvh::anyHit(bvh_, ray);
  };
  if (!seen_.empty() && !landings.empty() && glm::length(seenModel_) > 0.0) {
    std::vector<Photon> photons;
    const std::uint32_t type = lights.lights[light].info.x;
    if (type == gpu::kLightDirectional || type == gpu::kLightBackground) {
      photons = beamPhotons(lights, light, rng);
      // The first landings keep the beams outside the seen box's shadow (the strata beamPhotons drew apart).
      const double perRay = type == gpu::kLightDirectional
                                ? std::numbers::pi * sceneRadius() * sceneRadius() / emitted // irradiance 1 x the disk's share
                                : static_cast<double>(lights.unitFlux[light].x) / emitted;
      for (const Landing& h : landings) {
        if (beamCrossesSeenBox(h.from, h.direction)) continue;
        photons.push_back({h.position, h.normal, h.reflectance, glm::dvec3(perRay),
                           std::numbers::pi * sceneRadius() * sceneRadius() / emitted / std::numbers::pi});
      }
    } else {
      const glm::dvec3 flux = glm::dvec3(lights.unitFlux[light]) * (1.0 - reach.escapeDirect) / static_cast<double>(landings.size());
      const double rc2 = reach.area / (std::numbers::pi * static_cast<double>(landings.size()));
      for (const Landing& h : landings) photons.push_back({h.position, h.normal, h.reflectance, flux, rc2});
    }
    glm::dvec3 target(0.0);
    for (const SurfacePoint& p : seen_) {
      glm::dvec3 sum(0.0);
      for (std::uint32_t k = 0; k < kSeenLandingsPerPoint && !photons.empty(); ++k) {
        const Photon& h = photons[rng.below(static_cast<std::uint32_t>(photons.size()))];
        glm::vec3 d = h.position - p.position;
        const float r2 = glm::dot(d, d);
        if (!(r2 > 0.0f)) continue;
        d /= std::sqrt(r2);
        const float cosP = glm::dot(p.normal, d), cosL = -glm::dot(h.normal, d);
        if (cosP <= 0.0f || cosL <= 0.0f) continue;
        glm::vec3 from = p.position + offsetAt(p.position, offset_) * p.normal;
        glm::vec3 to = h.position + offsetAt(h.position, offset_) * h.normal;
        if (!visible(from, to)) continue;
        sum += h.flux * glm::dvec3(h.reflectance) * static_cast<double>(cosP * cosL) / std::max(static_cast<double>(r2), h.rc2);
      }
      // Photons drawn uniformly: the sum over all of them is photons / K times this one.
      const glm::dvec3 e1 = sum * (static_cast<double>(photons.size()) / kSeenLandingsPerPoint) / std::numbers::pi;
      target += glm::dvec3(p.reflectance) * e1 / std::numbers::pi;
    }
    for (int c = 0; c < 3; ++c) reach.seenFirstBounce[c] = seenModel_[c] > 0.0 ? static_cast<float>(target[c] / seenModel_[c]) : 0.0f;
    reach.seenBounce = seenBounce_;
    reach.seenFitted = true;
  }
  return reach;
}

float ReachedSurfaces::sceneRadius() const {
  const scene::Bounds& b = scene_->bounds;
  return 0.5f * glm::length(b.hi - b.lo) + 1e-3f; // samplePoint's sphere and disk
}

// The rectangle, in the plane across `direction` through the scene's centre (frame t, b), that
// the seen box projects to, clipped to the disk of the scene's radius; area 0 when empty.
ReachedSurfaces::BeamRect ReachedSurfaces::seenBoxAcross(glm::vec3 direction) const {
  const scene::Bounds& bounds = scene_->bounds;
  const glm::vec3 centre = 0.5f * (bounds.lo + bounds.hi);
  BeamRect r;
  Frame f = frameAround(direction);
  r.t = f.t;
  r.b = f.b;
  r.lo = glm::vec2(std::numeric_limits<float>::max());
  r.hi = glm::vec2(-std::numeric_limits<float>::max());
  for (int corner = 0; corner < 8; ++corner) {
    glm::vec3 c((corner & 1) ? seenHi_.x : seenLo_.x, (corner & 2) ? seenHi_.y : seenLo_.y, (corner & 4) ? seenHi_.z : seenLo_.z);
    glm::vec2 uv(glm::dot(c - centre, f.t), glm::dot(c - centre, f.b));
    r.lo = glm::min(r.lo, uv);
    r.hi = glm::max(r.hi, uv);
  }
  const float radius = sceneRadius();
  r.lo = glm::max(r.lo, glm::vec2(-radius));
  r.hi = glm::min(r.hi, glm::vec2(radius));
  return r;
}

bool ReachedSurfaces::beamCrossesSeenBox(glm::vec3 from, glm::vec3 direction) const {
  const scene::Bounds& bounds = scene_->bounds;
  const BeamRect r = seenBoxAcross(direction);
  const glm::vec3 centre = 0.5f * (bounds.lo + bounds.hi);
  glm::vec2 uv(glm::dot(from - centre, r.t), glm::dot(from - centre, r.b));
  return r.area() > 0.0f && uv.x >= r.lo.x && uv.x < r.hi.x && uv.y >= r.lo.y && uv.y < r.hi.y;
}

// Lights from outside the scene (directional, sky) as parallel beams across a disk of the scene's
// radius (the sky: a beam for every direction, uniform, radiance 1 times 4 pi; the sun: its one
// direction, irradiance 1). A room in a large world (classroom's 221 m ground) gets almost none of
// the first landings, so the beams that cross the seen box (grown by dmax) are drawn apart:
// kSeenBeamRays uniform over the box's projection, each carrying irradiance x projected area / N;
// measure() keeps the first landings outside that stratum. Landings only (misses carry nothing).
std::vector<ReachedSurfaces::Photon> ReachedSurfaces::beamPhotons(const LightSet& lights, std::size_t light, StreamRng& rng) const {
  auto uni = [](StreamRng& r) { return r.next(); };
  const scene::Bounds& bounds = scene_->bounds;
  const glm::vec3 centre = 0.5f * (bounds.lo + bounds.hi);
  const float radius = sceneRadius();
  const bool sky = lights.lights[light].info.x == gpu::kLightBackground;
  std::vector<Photon> out;
  for (std::uint32_t i = 0; i < kSeenBeamRays; ++i) {
    const glm::vec3 direction = sky ? sphereDirection(uni(rng), uni(rng)) : glm::normalize(glm::vec3(lights.lights[light].direction));
    const BeamRect r = seenBoxAcross(direction);
    if (!(r.area() > 0.0f)) continue;
    glm::vec2 uv(r.lo.x + uni(rng) * (r.hi.x - r.lo.x), r.lo.y + uni(rng) * (r.hi.y - r.lo.y));
    if (glm::dot(uv, uv) > radius * radius) continue; // outside the disk: no light there
    bvh::Ray ray{.origin = centre - 2.0f * radius * direction + uv.x * r.t + uv.y * r.b, .direction = direction};
    bvh::Hit hit = bvh::closestHit(bvh_, ray);
    if (!hit.hit()) continue;
    const glm::uvec3 tri = scene_->triangles[hit.primitive];
    glm::vec3 a = scene_->positions[tri.x], b = scene_->positions[tri.y], c = scene_->positions[tri.z];
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    if (glm::dot(n, direction) > 0.0f) n = -n;
    const double share = static_cast<double>(r.area()) / kSeenBeamRays; // cross-section per ray
    const double flux = (sky ? 4.0 * std::numbers::pi : 1.0) * share;
    out.push_back({ray.origin + hit.t * direction, n, reflectance_[hit.primitive], glm::dvec3(flux), share / std::numbers::pi});
  }
  return out;
}

void ReachedSurfaces::setSeenView(const SeenView& view) {
  seen_.clear();
  seenModel_ = glm::dvec3(0.0);
  seenLo_ = glm::vec3(std::numeric_limits<float>::max());
  seenHi_ = glm::vec3(-std::numeric_limits<float>::max());
  const scene::Scene& scene = *scene_;
  const GridCamera camera{view.position, view.forward, view.up, view.yfov, view.aspect};
  glm::dvec3 bounce(0.0);
  std::size_t bounceRays = 0;
  std::mt19937 rng(0x5ee9u);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (std::uint32_t y = 0; y < kSeenGrid; ++y)
    for (std::uint32_t x = 0; x < kSeenGrid; ++x) {
      // A jittered grid over the image.
      const float gx = static_cast<float>(x) + uni(rng);
      const float gy = static_cast<float>(y) + uni(rng);
      const auto hit = firstHitThroughGrid(scene, bvh_, camera, gx, gy, static_cast<int>(kSeenGrid));
      if (!hit) continue;
      const glm::vec3 n = hit->normal;
      const SurfacePoint p{hit->position, n, reflectance_[hit->primitive]};
      // W_c (or W) at P as obscurance.glsl estimates it: cosine rays of length dmax.
      glm::dvec3 w(0.0);
      for (std::uint32_t k = 0; k < kSeenObscuranceRays; ++k) {
        // What comes back at all (any distance): the later bounces' q.
        bvh::Hit any = bvh::closestHit(bvh_, {.origin = p.position + offsetAt(p.position, offset_) * n,
                                              .direction = cosineDirection(n, uni(rng), uni(rng))});
        if (any.hit()) bounce += glm::dvec3(reflectance_[any.primitive]);
        ++bounceRays;
        glm::vec3 dir = cosineDirection(n, uni(rng), uni(rng));
        bvh::Hit q = bvh::closestHit(bvh_, {.origin = p.position + offsetAt(p.position, offset_) * n, .direction = dir,
                                            .tmin = 0.0f, .tmax = view.dMax});
        glm::vec3 r = view.colourBleeding ? view.averageReflectance : glm::vec3(1.0f);
        float rho = 1.0f;
        if (q.hit()) {
          rho = obscuranceRho(q.t, view.dMax, view.rho, view.tau);
          r = view.colourBleeding ? reflectance_[q.primitive] : glm::vec3(1.0f);
        }
        w += glm::dvec3(r) * static_cast<double>(rho);
      }
      seenModel_ += glm::dvec3(p.reflectance) * w / static_cast<double>(kSeenObscuranceRays);
      seen_.push_back(p);
      seenLo_ = glm::min(seenLo_, p.position - glm::vec3(view.dMax));
      seenHi_ = glm::max(seenHi_, p.position + glm::vec3(view.dMax));
    }
  seenBounce_ = bounceRays ? glm::vec3(bounce / static_cast<double>(bounceRays)) : glm::vec3(0.0f);
}

} // namespace obscura::render

