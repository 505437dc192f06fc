// lane_order.h — how much of the 8-lane SIMD groups the rays of a frame keep busy, in the order
// the passes trace them and in coherent alternatives (issue 10, "coherent order").
//
// lavapipe runs 8 invocations in lock-step, and a traversal loop runs until the slowest lane's
// ray is done (LAVAPIPE.md), so a group of 8 rays costs 8 x its longest ray. Utilisation = mean
// loop passes per ray / mean of the group maxima. The frame's rays (sample 0 of
// bench/frame_rays.h: camera rays, then N_obs obscurance rays at each hit, around the geometric
// normal) are traced by trace.comp with its step counts, in each order below; a group is 8
// consecutive rays, as a pass's 8 consecutive invocations are (one ray per lane: the figures
// model the passes; trace.comp itself refills its lanes, so its gpuMs is that loop's time).
#pragma once
#include <string>
#include <vector>

#include "bench/frame_rays.h"
#include "render/ray_tracer.h"
#include "scene/scene.h"

namespace obscura::bench {

struct LaneOrderFigures {
  std::string name;       // which rays, in which order
  std::size_t rays = 0;   // real rays (lanes without one are left out of the figures)
  double meanSteps = 0.0; // loop passes per ray
  double groupSteps = 0.0; // loop passes per 8-lane group (its longest ray)
  double gpuMs = 0.0;     // trace.comp (refilling) on them in this order (best of `repeats`)
  double utilisation() const { return groupSteps > 0.0 ? meanSteps / groupSteps : 0.0; }
};

// Orders measured: camera rays by rows of 8 pixels (the passes' 8 x 8 workgroups, x fastest),
// by 4 x 2 tiles; obscurance rays as the obscurance pass traces them (ray i of 8 neighbouring
// pixels of a row, i = 0 .. N_obs - 1), by 4 x 2 tiles, and sorted over the frame by origin cell
// (a 1024^3 grid over the scene's box, Morton order) and direction octant (either first).
std::vector<LaneOrderFigures> measureLaneOrders(render::RayTracer& tracer, const scene::Scene& scene,
                                                const ObscuranceFrameWork& work, int repeats);

} // namespace obscura::bench
