// photo_gather.h — the indirect light at each pixel gathered from the photographs themselves
// (OURS, replacing the paper's constant ambient [IVR §4.2]; the paper's future work):
//
//   B_i(P) = 1/pi  int L_i(Q) cos dw  ~  1/N sum_k L_i(Q_k)     (N cosine-distributed rays from P)
//
// where Q_k is the first surface a ray meets and L_i(Q) its radiance in photo i. Where the camera
// sees Q (the pixel Q projects to shows the same object on the same plane), L_i(Q) is the
// photograph's pixel: measured radiance, with every bounce in it, no model. Elsewhere (hidden
// from the camera) it is modelled as R_o (F V E_i(Q) + B_i(Q)): the current mean reflectance of
// Q's object, the lamp's direct light (a shadow ray) and Q's own indirect light B_i(Q), which is
// the same estimate one vertex on: a path through the surfaces the camera does not see, one
// cosine-distributed ray per vertex, until it meets a surface the camera sees (the photograph's
// radiance ends it), leaves the room (black), or reaches `hiddenBounces` vertices past Q (cut
// there). One path per hidden hit is a noisy estimate, but a pixel averages its tens of hidden
// hits and the smoothing below pools a window of pixels.
//
// The cut: the light a path would have brought on from its last vertex, which belongs to an object
// o, is taken as c_o, the mean incoming indirect light of the hidden vertices on o whose paths went
// on (a radiance cache of one value per object, settled over the caller's iterations: each gather
// returns the c_o its own paths found, to cut the next one with). One value per object is too
// coarse where one object spans light and dark: the modern hall's walls and ceiling are one
// object, and a path cut in the dark corner above its staircase (photographs 1/30 of the walls')
// brought the whole hall's mean, B 2-3x what the photographs imply there. So the cache is also
// kept per region, an object's part facing one of the six axis directions in one cell of a grid
// over what the camera sees (kCutCells along its longest side; not over the model's bounds, which
// may hold far more: the classroom's 221 m ground made its whole room one cell, and its hallway,
// seen through the windows, came out 10 % dark), each region's value shrunk towards its object's
// where it has few paths.
// The first design cut with b_i, the mean indirect light of the pixels, and with
// hiddenBounces = 0 gave every hidden Q b_i: that
// lit hidden surfaces in shadow (under desks, behind objects) and whole dark regions (classroom's
// hallway, seen through its windows, where the photographs are 1/20 of the walls) as brightly as
// the room's average, and biased B up where most rays are hidden (69-88 % in a large room).
// Rays that leave the scene see nothing (the photographs' world is black).
//
// The rays depend on the geometry only: they are traced once, through a RayBatch (the device's
// traversal, render/gpu_ray_batch.h, or the CPU's twin), and each recovery iteration (new R_o,
// b_i) re-sums them without a ray.
//
// The estimate's variance comes from bright spots (near a lamp the walls are 30x the median) met
// by few rays. Indirect light varies slowly over a surface, so B_i is then averaged over a
// (2 radius + 1)^2 window of pixels that see the same object with the same normal (dot > 0.95):
// the window's rays pool, and edges between surfaces stay sharp.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "core/names.h"
#include "gpu/context.h"
#include "recover/photo_set.h"
#include "render/scene_data/ray_batch.h"
#include "scene/scene.h"

namespace obscura::recover {

// What the camera sees per pixel (the renderer's AOVs): the point, its normal facing the camera,
// and the object (-1 for none).
struct PixelGeometry {
  int width = 0, height = 0;
  std::vector<glm::vec3> position, normal;
  std::vector<std::int32_t> object;
};

// The longest path through hidden surfaces (`hiddenBounces`' range), and the default: at a
// reflectance of ~0.7 the cut vertex carries 0.7^3 = 1/3 of the cut's weight at the first.
inline constexpr std::uint32_t kMaxHiddenBounces = 8;
inline constexpr std::uint32_t kDefaultHiddenBounces = 3;
// A first hidden vertex's lamps that each give it at least this share of its unoccluded light get
// a shadow ray of their own; one ray samples the rest (PhotoGather's constructor; 0: every lamp
// its own ray).
inline constexpr float kExactShare = 0.25f;

class PhotoGather {
public:
  // The pixels' gather rays, their hidden hits' paths and shadow rays through `rays` (about
  // kRaysPerBatch gather rays at a time).
  PhotoGather(const scene::Scene& room, render::RayBatch& rays, const scene::Camera& camera, const PixelGeometry& pixels,
              const std::vector<Shot>& shots, std::uint32_t raysPerPixel, std::uint32_t seed, int smoothRadius,
              std::uint32_t hiddenBounces = kDefaultHiddenBounces, float exactShare = kExactShare);
  // The same with the rays on `context`'s device, through the renderer's traversal of the room's
  // buffers (uploaded for this and dropped after).
  static PhotoGather onDevice(const gpu::Context& context, const scene::Scene& room, const bvh::Bvh& bvh,
                              const scene::Camera& camera, const PixelGeometry& pixels, const std::vector<Shot>& shots,
                              std::uint32_t raysPerPixel, std::uint32_t seed, int smoothRadius,
                              std::uint32_t hiddenBounces = kDefaultHiddenBounces);
  // Gather rays traced together (a 256 x 256 view's 64 per pixel in 4 batches): few submissions,
  // and the rays and hits of one batch in tens of MiB of host memory.
  static constexpr std::size_t kRaysPerBatch = std::size_t(1) << 20;

  // The cut (see above): the incoming indirect light (per unit reflectance, radiance units) a path
  // cut at a vertex brings: c_o per object, and per region (the object's part in one grid cell,
  // this gather's regions) where a gather settled one; a cut without regions is its objects'.
  struct Cut {
    std::vector<glm::vec3> object;
    std::vector<glm::vec3> region;
  };
  // A cut of one value b for every one of `objects` objects (the first design's, to start from).
  static Cut uniformCut(std::size_t objects, glm::vec3 b) { return {std::vector<glm::vec3>(objects, b), {}}; }
  // Cells of the regions' grid along the longest side of what the camera sees (cubic cells).
  static constexpr float kCutCells = 16.0f;

  // B_i per pixel for every shot (per unit reflectance, radiance units), with the photographs'
  // radiance where the camera sees the hit, and objectReflectance and cut[i] elsewhere; with
  // `settled`, also the cut these paths found for each shot (gather's).
  // With `modelled`, also each B_i's modelled share per pixel (gather's `modelled`).
  std::vector<std::vector<glm::vec3>> indirect(const std::vector<Shot>& shots,
                                               const std::vector<glm::vec3>& objectReflectance,
                                               const std::vector<Cut>& cut, std::vector<Cut>* settled = nullptr,
                                               std::vector<std::vector<float>>* modelled = nullptr) const;
  // One gather of an arbitrary lighting (relighting the recovered room, remodel.h): B(P) with
  // `radiance` the current radiance of the pixels the camera sees, and at hidden hits
  // objectReflectance x (sum_i lampColour[i] x the shot-i lamp's direct light + what comes in:
  // the path's next vertex, or `cut` at its last). With `settled`, also the cut these paths found:
  // per object, the mean incoming light of its vertices whose paths went on, shrunk towards the
  // pixels' mean B where they are few (kCutPrior vertices' worth; an object no path went on from,
  // or every object with hiddenBounces = 0, gets that mean: the first design's cut); per region
  // the same of its own vertices, shrunk towards its object's value.
  // indirect() is this with photo i's radiance and only lamp i.
  // With `modelled`, also the share of each pixel's B (its luminance, smoothed as B is) that rests
  // on the model's longer reach: what the hidden hits pass on beyond their own direct light (the
  // light of their paths' deeper vertices and of the cut, each times an object mean). The rest is
  // measured (the photographs' radiance where the camera sees the hit) or one exact shadow ray
  // times one object mean. Where a lamp lights a pixel only along such paths (the staircase's
  // wall around the arch in its five far shots) B came out 1.3-1.5x the photographs' indirect
  // light, where the near shot's was within 10 % (BENCHMARKS).
  std::vector<glm::vec3> gather(const std::vector<glm::vec3>& radiance, const std::vector<glm::vec3>& lampColour,
                                const std::vector<glm::vec3>& objectReflectance, const Cut& cut,
                                Cut* settled = nullptr, std::vector<float>* modelled = nullptr) const;
  static constexpr double kCutPrior = 32.0;
  // Points of a pixel's footprint its gather rays start from, each a few rays (a camera ray per
  // gather ray made the staircase's gather 15-25 % slower for 1 % less RMSE on the classroom).
  static constexpr std::uint32_t kPointsPerPixel = 4;
  // Fractions of the rays whose hit the camera sees, that are hidden, and that leave the scene.
  double seenFraction() const { return double(seen_.size()) / double(rays_); }
  double hiddenFraction() const { return double(firstHidden_) / double(rays_); }
  std::uint64_t rays() const { return rays_; }
  // The object of each region of the cut (Cut::region's order).
  const std::vector<std::uint32_t>& regionObjects() const { return regionObject_; }

private:
  // next_[v]: where the path goes on from hidden vertex v.
  static constexpr std::uint32_t kEscaped = ~0u;        // the ray left the room
  static constexpr std::uint32_t kTruncated = ~0u - 1u; // cut at the last depth: the object's c_o
  static constexpr std::uint32_t kSeenFlag = 1u << 31;  // | the pixel that shows the next hit
  // Otherwise the next hidden vertex's index.
  // Every hidden vertex's radiance towards where its ray came from, folded from the paths' ends
  // (a vertex's next one always has a larger index); with `sums`, also per object the sum of
  // the incoming light of its vertices whose paths went on (`incoming`) and how many there were
  // (`paths`), and the same per region.
  struct CutSums {
    std::vector<glm::dvec3> incoming, regionIncoming;
    std::vector<double> paths, regionPaths;
  };
  std::vector<glm::vec3> hiddenRadiance(const std::vector<glm::vec3>& radiance, const std::vector<glm::vec3>& lampColour,
                                        const std::vector<glm::vec3>& objectReflectance, const Cut& cut,
                                        CutSums* sums) const;
  // The shots whose lamp `lampColour` lights (the others' direct light adds nothing).
  std::vector<std::size_t> litShots(const std::vector<glm::vec3>& lampColour) const;

  const PixelGeometry* geometry_;
  int smoothRadius_ = 0;
  std::size_t pixels_ = 0, shots_ = 0;
  std::uint32_t raysPerPixel_ = 0;
  std::uint64_t rays_ = 0;
  // Per pixel p, its seen hits are seen_[seenStart_[p] .. seenStart_[p + 1]) (pixel indices), its
  // hidden hits hiddenObject_/hiddenDirect_ [hiddenStart_[p] .. hiddenEnd_[p]) (hiddenDirect_:
  // [shot * vertices + vertex] once built, per vertex while the constructor fills it; the
  // lamp's unit-reflectance direct light F V I / pi there, without
  // the lamp's colour; at a first vertex its main lamps' (kExactShare) and one of the rest's,
  // weighted, at a deeper vertex one lamp's, weighted, the others 0: see the constructor).
  // Deeper path vertices follow each chunk's pixels, outside every range.
  std::vector<std::uint32_t> seenStart_, seen_;
  std::vector<std::uint32_t> hiddenStart_, hiddenEnd_, hiddenObject_;
  // Each hidden vertex's region (the cut's), and each region's object.
  std::vector<std::uint32_t> hiddenRegion_, regionObject_;
  std::vector<float> hiddenDirect_;
  // The hidden vertices' paths (the first vertices are the pixels' ranges above; deeper ones
  // follow each chunk's), and how many first vertices there are.
  std::uint32_t hiddenBounces_ = kDefaultHiddenBounces;
  std::vector<std::uint32_t> next_;
  std::uint64_t firstHidden_ = 0;
};

// `image` averaged over the (2 radius + 1)^2 window's pixels that see the same object as the
// centre with a normal within dot 0.95 of its own.
std::vector<glm::vec3> smoothOnSurfaces(const std::vector<glm::vec3>& image, const PixelGeometry& pixels, int radius);

// The pixel a world point projects to in `camera` at width x height (as camera.glsl makes the
// primary rays), or -1 when it is behind the camera or outside the image.
std::int64_t projectToPixel(const scene::Camera& camera, int width, int height, const glm::vec3& point);

} // namespace obscura::recover
