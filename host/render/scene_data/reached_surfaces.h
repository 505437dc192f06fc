// reached_surfaces.h — the surfaces each light actually reaches, for the ambient term: the paper's
// future work [RTO §6, SPEC §1.6] "I_a and R_ave from the surfaces that light actually reaches".
//
// The paper's I_a spreads every light's flux over the whole scene's area A_t with the whole
// scene's mean reflectance. In a building with many rooms, or a scene whose bounding geometry is
// mostly never lit, that dilutes the ambient light of the lit room. Here, per light s:
//   1. light rays: points on the light, directions by its emission (cosine about an area light's
//      normal, uniform for a point light, within a spot's cone, along a directional light), each
//      traced to its first hit: where the light lands directly;
//   2. surface samples: points uniform by area over the whole scene (shared by all lights); a
//      point is reached when it sees a point of the light or one of the first hits (so what the
//      light reaches after one bounce counts too), tested with a few shadow rays;
//   3. A_s = A_t x (fraction of surface samples reached), R_s = mean reflectance of those;
//   4. what leaves: e_0, the share of light rays that hit nothing, and e_1, the share of cosine
//      rays from the landing points that hit nothing (an open scene, a window, the Cornell box's
//      open front lose that light; the paper's I_a assumes a closed scene).
// I_a's weight for light s then uses A_s, R_s and the escapes in place of A_t and R_ave
// (ambient.h): flux (1 - e_0) / (pi A_s) / (1 - R_s (1 - e_1)), which keeps I_a linear in every
// emission.
//
// The Seen refinement (OURS, AmbientModel::Seen): a light's flux does not spread evenly over what
// it reaches. A lamp in a basement or a skylight over a stairwell lights its own corner; the rest
// of the reached area sees that light only after several bounces, or through a gap at a grazing
// angle. So, for the points the camera sees, the one-bounce irradiance from light s is measured
// with the landing points of step 1 as virtual point lights (each carrying flux/emitted, reflected
// by its surface's R, one shadow ray to a few of them per point), and the first-bounce term of
// I_a is fitted to it: the ambient term's first bounce is R(P) x W_c(P) x F_s, so
//   F_s = sum_P R(P) E_1,s(P) / pi  /  sum_P R(P) W_c(P)          (per channel)
// with W_c (or W, grey) measured at the same points with the render's rho and dmax. The sun and
// the sky, whose rays spread over the whole world and seldom land where the camera looks, are
// gathered the other way: from where the seen points' cosine rays land, one shadow ray to the
// light there (gatheredFirstBounce). F_s replaces
// flux (1 - e_0) / (pi A_s) and I_a's weight is F_s x the same series of later bounces. F_s is
// still linear in the light's emission (flux per landing), so relighting holds; it is fitted to
// one camera (like the default dmax). The rays run on the CPU (bvh::closestHit / anyHit): a few
// thousand per light, deterministic for a given scene (fixed seeds), so an incremental edit and a
// fresh render agree. They are traced a stage at a time through a RayBatch (ray_batch.h): the
// renderer's on the GPU, or the CPU's BVH (the calls without one, and the tests' twin).
//
// Every ray draws its random numbers from a stream of its own (the light's name, the kind of ray
// and its index), so no ray's outcome shifts another's numbers. That is what lets a geometry edit
// re-measure a light exactly by re-tracing only the rays the edit can change (remeasure): a ray
// whose segment meets none of the changed boxes, from a sample point and to a target that did not
// move, finds in the edited scene what it found before.
#pragma once
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "render/scene_data/light_set.h"
#include "render/scene_data/ray_batch.h"
#include "scene/scene.h"

namespace obscura::render {

// What each ray of a light's measurement found, kept so that an edit can re-trace only the rays
// it may change (ReachedSurfaces::remeasure).
struct ReachRays {
  std::vector<float> landingT;                   // per light ray: distance to its first hit; inf: none,
                                                 // NaN: nothing emitted (a spot gave no direction)
  std::vector<std::uint32_t> landingPrimitive;   // per light ray: the triangle it landed on
  std::vector<float> bounceBlockedAt;            // per light ray that landed: where its reflected ray
                                                 // was found blocked (inf: it left the scene)
  std::vector<std::uint8_t> firstSeenTry;        // per surface sample: the try that saw the light or
                                                 // a landing (kNotSeen: none did)
  std::vector<float> tryBlockedAt;               // per surface sample and try (kTries each): where
                                                 // along its segment (0..1) it was found blocked; NaN:
                                                 // not traced (skipped, or after the seen one)
  std::uint64_t traced = 0;                      // rays this measurement traced (re-traced ones only
                                                 // for remeasure)
  // The rays themselves, so that a replay tests each one's segment against the changed boxes
  // without drawing it again: drawing every light's rays anew was ~90 % of a move's host work
  // (modern-hall's 13 lights, ~24 ms; BENCHMARKS). ~0.3 MB a light.
  std::vector<bvh::Ray> lightRay;                // per light ray as emitted (only where landingT is not NaN)
  std::vector<glm::vec3> bounceDirection;        // per light ray that landed: its reflected ray's direction
  std::vector<std::uint64_t> landingTryDraws;    // per surface sample: its stream after the light tries,
                                                 // where the tries at landings draw their light rays
  std::vector<scene::Bounds> triedBounds;        // per surface sample: the box around the segments of
                                                 // the tries that decided it (a blocked one up to where
                                                 // it was blocked); a replay keeps a sample whose box
                                                 // meets no changed box without looking at its tries
};

struct LightReach {
  double area = 0.0;              // A_s: area the light reaches (directly or after one bounce)
  glm::vec3 reflectance{0.0f};    // R_s: mean reflectance of that area
  double fraction = 0.0;          // A_s / A_t
  double escapeDirect = 0.0;      // e_0: share of the light's rays that leave the scene unhit
  double escapeBounce = 0.0;      // e_1: share of rays diffusely reflected where it lands that leave
  // Where the light rays landed: (triangle, rays) for every triangle hit, by triangle, of
  // `landings` rays that hit something (secondary_reflectors.h marks the strongly lit ones).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> landedTriangles;
  std::uint32_t landings = 0;
  // Seen: the fitted first-bounce term F_s (see above); valid when seenFitted.
  glm::vec3 seenFirstBounce{0.0f};
  // Seen: q of the later bounces around the seen points, R (1 - e) of unbounded cosine rays from
  // them (the same for every light: bounces after the first happen where the camera looks).
  glm::vec3 seenBounce{0.0f};
  bool seenFitted = false;
  ReachRays rays;
};

class StreamRng; // reached_surfaces.cpp: a random stream per ray

// The camera's view for the Seen fit: where its rays land and the obscurance settings there.
struct SeenView {
  glm::vec3 position{0.0f}, forward{0.0f, 0.0f, -1.0f}, up{0.0f, 1.0f, 0.0f};
  float yfov = 0.8f, aspect = 1.0f;
  float dMax = 1.0f;
  std::uint32_t rho = 0;  // gpu::kRhoSqrt, kRhoExp or kRhoAo
  float tau = 3.0f;
  bool colourBleeding = true;
  glm::vec3 averageReflectance{0.5f}; // R(Q) of a miss within dmax
  bool darkEscapes = false;           // a miss within dmax that leaves the scene brings nothing
  bool operator==(const SeenView&) const = default;
};

// rho(d) [RTO §3], the C++ twin of shaders/lib/obscurance.glsl's rho().
float obscuranceRho(float d, float dMax, std::uint32_t kind, float tau);

class ReachedSurfaces {
public:
  // `reflectance[t]`: mean reflectance of triangle t (ambient.h, triangleReflectances). The scene
  // must outlive it (as it outlives the renderer). The calls without a RayBatch trace the CPU's
  // BVH: a copy of `bvh` (so that they may run on threads while the caller's changes), or, with
  // `copyBvh` false (all rays through a RayBatch: a copy would be an edit's O(n) host work),
  // `bvh` itself, which must then outlive it.
  ReachedSurfaces(const scene::Scene& scene, const bvh::Bvh& bvh, const std::vector<glm::vec3>& reflectance,
                  bool copyBvh = true);

  // What light `light` of `lights` reaches. Zero area when it reaches nothing (zero power, or
  // enclosed): the caller falls back to the whole scene.
  LightReach measure(RayBatch& rays, const LightSet& lights, std::size_t light) const;
  // The same on the CPU's BVH.
  LightReach measure(const LightSet& lights, std::size_t light) const;

  // The same measurement in this (edited) scene, from `previous`, what `before` (the scene before
  // the edit, with the same lights and emitters) measured for this light: only the rays that can
  // have changed are traced again, those whose segment meets one of `changed` (the edited
  // objects' old and new boxes, padded by the caller for ray offsets) or whose end points moved.
  // The result equals measure() on this scene bit for bit (ReachedSurfaces.Remeasure* test it).
  LightReach remeasure(RayBatch& rays, const ReachedSurfaces& before, const LightReach& previous,
                       const LightSet& lights, std::size_t light, const std::vector<scene::Bounds>& changed) const;
  LightReach remeasure(const ReachedSurfaces& before, const LightReach& previous, const LightSet& lights,
                       std::size_t light, const std::vector<scene::Bounds>& changed) const;

  double totalArea() const { return totalArea_; }

  // Seen points for the Seen fit (measure() then fits F_s); without them measure() leaves
  // seenFitted false.
  void setSeenView(RayBatch& rays, const SeenView& view);
  void setSeenView(const SeenView& view);
  // The BVH the CPU's rays run through (a copy of the one it was made with).
  const bvh::Bvh& bvh() const { return bvhCopy_ ? *bvhCopy_ : *callersBvh_; }
  std::size_t seenPoints() const { return seen_.size(); }
  std::size_t surfaceSamples() const { return samples_.size(); }
  // The surface samples on triangles [first, first + count).
  std::size_t samplesOn(std::uint32_t first, std::uint32_t count) const;

  // Light rays per light and surface samples over the scene (OURS: a few thousand keep the
  // estimate within a percent or two of the reached fraction, tested, at ~0.01 s per light). The
  // samples are kSurfaceSamples in expectation (drawn triangle by triangle, see the constructor).
  static constexpr std::uint32_t kLightRays = 1024;
  static constexpr std::uint32_t kSurfaceSamples = 4096;
  static constexpr std::uint32_t kVisibilityTries = 4; // shadow rays per sample and kind of target
  static constexpr std::uint8_t kNotSeen = 0xff;
  static constexpr std::uint32_t kTries = 2 * kVisibilityTries; // light points, then landing points
  // Seen fit: camera points (a grid), obscurance rays at each, landings (virtual point lights)
  // tested from each (OURS: ~16k shadow rays per light; the fit's spread over seeds is a few %);
  // the sun and the sky: one shadow ray where each of the points' kSeenObscuranceRays landed.
  static constexpr std::uint32_t kSeenGrid = 24;
  static constexpr std::uint32_t kSeenObscuranceRays = 16;
  static constexpr std::uint32_t kSeenLandingsPerPoint = 32;

private:
  struct SurfacePoint {
    glm::vec3 position, normal, reflectance;
    bool operator==(const SurfacePoint&) const = default;
  };
  struct Replay; // what remeasure reuses
  // The point a light try of `sample` aims at, drawn from the sample's stream; NaN: none (the
  // sample is behind the light's point, or outside a spot's cone).
  glm::vec3 lightTryTarget(const LightSet& lights, std::size_t light, const SurfacePoint& sample, StreamRng& rng) const;
  LightReach trace(RayBatch& rays, const LightSet& lights, std::size_t light, const Replay* replay) const;
  // Where a seen point's cosine ray landed: the sun's and the sky's first bounce is gathered there
  // (gatheredFirstBounce).
  struct SeenGather {
    glm::vec3 position; // off the surface, on the side the ray came from
    glm::vec3 normal;   // facing the seen point
    glm::dvec3 weight;  // its share of sum_P R(P) E_1(P) / pi per unit of direct irradiance there
  };
  // The Seen fit's target, sum_P R(P) E_1(P) / pi, for a light inside the scene (from its landings)
  // and for the sun and the sky (gathered).
  glm::dvec3 landingsFirstBounce(RayBatch& rays, const std::vector<SurfacePoint>& landings, glm::dvec3 flux, double rc2,
                                 std::uint32_t seed, std::uint64_t& traced) const;
  glm::dvec3 gatheredFirstBounce(RayBatch& rays, const LightSet& lights, std::size_t light, std::uint32_t seed,
                                 std::uint64_t& traced) const;
  const scene::Scene* scene_;
  std::optional<bvh::Bvh> bvhCopy_;
  const bvh::Bvh* callersBvh_; // bvh(): the copy when there is one
  std::vector<SurfacePoint> samples_;
  std::vector<std::uint64_t> sampleKeys_; // per sample: triangle << 32 | its number on it, ascending
  static std::uint32_t sampleStream(std::uint64_t key); // the index of its streams
  std::vector<glm::vec3> reflectance_; // per triangle
  std::vector<SurfacePoint> seen_;        // camera points (reflectance = R(P))
  std::vector<SeenGather> seenGathers_;   // where their cosine rays landed
  glm::dvec3 seenModel_{0.0};             // sum_P R(P) W_c(P): the model's first bounce per unit F_s
  glm::vec3 seenBounce_{0.0f};            // q around the seen points (LightReach::seenBounce)
  double totalArea_ = 0.0;
  scene::Bounds bounds_; // the scene's: where the sky's and the sun's light points lie
  float offset_ = 1e-5f; // ray-origin offset along the normal: 1e-5 of the scene's largest extent
};

} // namespace obscura::render
