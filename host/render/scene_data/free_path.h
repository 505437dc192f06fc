// free_path.h — the scale of a scene that matters for obscurances: how far a surface the camera
// sees is from the surfaces around it. The default dmax [SPEC §1.3] comes from it.
//
// The paper sets dmax to 1/4 .. 1/2 of the bounding box, which works for a closed room whose box
// is the room, and fails wherever the box is not the space the camera looks at: classroom's 221 m
// ground plane around a 10 m room, a building of many rooms. OURS: camera rays find the visible
// surfaces; from each, one cosine-distributed ray measures the distance to the next surface (a
// ray that leaves the scene counts as infinitely long). dmax = half the median of those distances.
// In a cubic room of side L seen from inside, cosine chords from its walls have a median near
// 0.6 L, so dmax ~ 0.3 L: inside the paper's 1/4 .. 1/2 of L, where the paper found it best.
#pragma once
#include <cstdint>

#include "bvh/bvh.h"
#include "scene/scene.h"

namespace obscura::render {

struct FreePath {
  float median = 0.0f;      // median distance to the next surface (infinite when most rays leave)
  double escaped = 0.0;     // share of the cosine rays that left the scene
  std::uint32_t rays = 0;   // cosine rays traced (camera rays that hit something)
  // Some rays left the scene: obscurance rays there are traced on past dmax (EscapeModel::Auto).
  bool open() const { return escaped > 0.0; }
};

// 48 x 48 camera rays through the image (aspect from the camera, 4:3 when it has none).
FreePath measureFreePath(const scene::Scene& scene, const bvh::Bvh& bvh, const scene::Camera& camera);

// Half the median free path seen from `camera`; a quarter of the largest bounding-box extent (the
// paper's) when the camera sees nothing or most rays leave the scene.
float defaultDMax(const scene::Scene& scene, const bvh::Bvh& bvh, const scene::Camera& camera);
// The same from a measurement made already.
float defaultDMax(const scene::Scene& scene, const FreePath& measured);

// The paper's: a quarter of the largest bounding-box extent.
float boundsDMax(const scene::Bounds& bounds);

} // namespace obscura::render
