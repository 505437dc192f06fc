// pixel_footprint.h — the surfaces a pixel's footprint covers, and the reflectance of a pixel that
// covers several (OURS).
//
// A photograph's pixel is the mean over its footprint of reflectance x light (a box filter over
// the pixel, as tools/cycles_photo.py renders and as a camera's sensor cell integrates), and the
// reflectance one recovers for it is the same mean of reflectance: where the footprint spans two
// surfaces, rho = sum_o a_o rho_o with a_o the share the footprint has on surface o. The estimate
// photo / (D + B) divides the mixed light by the light of the mean point's surface, so it is right
// only when both surfaces receive the same light; beside a shadow, at a chair's tube in front of a
// dark floor or a bright wall, it is not (the classroom's pixels whose footprint covers two
// surfaces had RMSE 0.100 against 0.062 overall, 18 % of its pixels and half its squared error).
// So such a pixel takes the mix of its surfaces' reflectances, each measured where the surface
// fills the whole footprint: the mean of that surface's whole pixels nearby, else its object's
// mean. What the footprint does not cover (the window's opening, the sky) contributes nothing, as
// in the photograph.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/scene_data/camera_grid.h"
#include "render/scene_data/ray_batch.h"
#include "scene/scene.h"

namespace obscura::recover {

// The camera of a width x height image as the renderer's primary rays see it (through
// render::gridRay, whose grid is the pixels: pixel (x, y) spans [x, x + 1) x [y, y + 1)).
render::GridCamera pixelCamera(const scene::Camera& camera, int width, int height);

struct PixelFootprints {
  // Points per pixel side: kGrid x kGrid points at the centres of the cells of a grid over the pixel.
  // The grid is the mixed pixels' floor: with the true reflectances, a 4 x 4 grid's mix is off by
  // 0.0248 RMSE on the Cornell box's mixed pixels, 8 x 8's by 0.0125 (BENCHMARKS, "the footprint's
  // own sampling floor"). Only pixels near an edge are traced at it (see traceFootprints).
  static constexpr int kGrid = 8;
  static constexpr int kPoints = kGrid * kGrid;
  // The grid every pixel is traced at first, to find the edges.
  static constexpr int kCoarseGrid = 4;
  int width = 0, height = 0;
  std::vector<std::int32_t> object; // [pixel * kPoints + point]: the object seen there, -1 none

  // Whether every point of pixel p sees the same object (a footprint on one surface).
  bool whole(std::size_t p) const;
  // whole(p) of every pixel.
  std::vector<bool> wholePixels() const;
};

// The footprints of every pixel, traced through `rays` adaptively: kCoarseGrid^2 camera rays per
// pixel, then kPoints on every pixel whose coarse points see more than one object, or one object
// and its left, right, upper or lower neighbour's another (an edge between two such pixels lies
// in one of them). Every other pixel has all its points on its one object. Returns the
// footprints and, in `refined`, how many pixels took the fine grid. A wire thinner than a
// quarter pixel that misses every coarse point is missed.
PixelFootprints traceFootprints(const scene::Scene& room, render::RayBatch& rays, const scene::Camera& camera,
                                int width, int height, std::size_t* refined = nullptr);

// Radius of the window a covered surface's whole pixels are averaged over, and how many it needs
// before its object's mean stands in (the classroom, the Cornell box and the staircase came out
// within 0.0003 RMSE of each other with radii 2, 4 and 8).
inline constexpr int kFootprintMixRadius = 4;
inline constexpr int kFootprintMixSupport = 3;

// Every pixel of `reflectance` whose footprint covers more than one object, or an object and
// nothing, set to the mix of its objects' reflectances (see above): of `object`'s pixels (the
// object at each pixel's centre) that are whole, within kFootprintMixRadius, else objectMeans.
// Pixels whose centre sees nothing (object -1) are left as they are. Returns how many were set.
std::size_t mixFootprints(const PixelFootprints& footprints, const std::vector<std::int32_t>& object,
                          const std::vector<glm::vec3>& objectMeans, std::vector<glm::vec3>& reflectance);

// The inverse of that mix, for the objects' means: every merged pixel whose footprint covers more
// than its centre's object o (and whose `weight` is above 0) set to o's share alone,
// rho_o = (rho - sum_{j != o} a_j objectMeans[j]) / a_o, clamped to [0, 1], its weight times a_o^2
// (the estimate's error grows as 1 / a_o), or 0 where a_o < kUnmixShare. A surface the camera sees
// only edge-on has no other pixels: the hall's switched-off panel across from the balustrade (base
// colour 0, a 1-pixel column) measured the wall behind it, 0.27, and the gather's paths through it
// lit the balustrade 7-26 % too brightly in every shot (BENCHMARKS, "the footprints unmixed").
// Returns how many pixels were unmixed.
inline constexpr float kUnmixShare = 0.25f;
std::size_t unmixFootprints(const PixelFootprints& footprints, const std::vector<std::int32_t>& object,
                            const std::vector<glm::vec3>& objectMeans, std::vector<glm::vec3>& reflectance,
                            std::vector<float>& weight);

} // namespace obscura::recover
