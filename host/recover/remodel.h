// remodel.h — the photographed room relit and remodelled with its recovered reflectance [IVR §5]:
// other lamps (a position never photographed), real objects removed, virtual objects inserted.
// Each pixel's radiance is
//
//   L(P) = R(P) (E(P) + B(P))
//
//   R  the recovered reflectance where the edited view still sees the surface the photographs
//      saw; an inserted object's own base colour; where a removed object uncovers a surface the
//      photographs never saw, synthesized from that surface elsewhere (texture_fill.h);
//   E  the lamps' direct light per unit reflectance, from the renderer's shadow rays in the
//      edited room (so inserted objects cast shadows, removed ones no longer do);
//   B  the indirect light per unit reflectance, gathered with recover's rays (photo_gather.h) in
//      the edited room, from the relit radiance itself: B_0 = 0, L_k = R (E + B_k),
//      B_{k+1} = gather(L_k), one more bounce per step [the rendering equation's Neumann series,
//      Kajiya 1986]. Hidden surfaces are their object's mean reflectance lit by shadow rays
//      and by paths on through hidden surfaces (photo_gather.h), cut per object as recover cuts
//      them. This is the gather that recover divides the photographs by, so relighting the room
//      under a photographed lamp gives back its photograph (where R came from that division).
// Lamps are glTF point lights (as recover's); inserted objects' textures are not read (their
// base colour factor is their reflectance).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "recover/photo_gather.h"
#include "recover/photo_set.h"
#include "scene/scene.h"

namespace obscura::recover {

// What recover found, in the view of the photographs.
struct RecoveredRoom {
  int width = 0, height = 0;
  std::vector<glm::vec3> reflectance;       // merged and filled (Recovery::reflectance)
  std::vector<std::uint8_t> measured;       // 1 where merged from the photographs (not filled)
  std::vector<std::int32_t> object;         // what each pixel saw (-1: nothing)
  std::vector<glm::vec3> objectReflectance; // each object's mean recovered reflectance
};

// The room as `recovery` found it.
struct Recovery;
RecoveredRoom recoveredRoom(const Recovery& recovery);

struct RemodelOptions {
  std::uint32_t spp = 16;        // samples per pixel of the direct light
  std::uint32_t seed = 1;
  std::uint32_t gatherRays = 64; // per pixel
  int gatherSmoothing = 3;       // photo_gather.h
  std::uint32_t bounces = 8;     // gathers (L has bounces + 1 reflections at most)
  // Path vertices through hidden surfaces per gather (photo_gather.h). Longer than recover's 3:
  // there the photographs end most paths, here nothing measures the new light, and the cut's
  // bias shrinks with each vertex (new lamp, median 8x8 block error 3 / 5 / 8 vertices, on the
  // first, 6-bounce photographs: classroom 4.6 / 3.9 / 3.7 %, staircase 3.9 / 3.9 / 3.4 %; ~1.5x
  // the time).
  std::uint32_t hiddenBounces = kMaxHiddenBounces;
};

struct RemodelledFrame {
  int width = 0, height = 0;
  std::vector<glm::vec3> radiance;        // R (E + B)
  std::vector<glm::vec3> reflectance;     // R
  std::vector<glm::vec3> direct, indirect;// E, B per unit reflectance
  std::vector<glm::vec3> obscurance;      // the renderer's obscurance term I_a W_c per unit
                                          // reflectance (what the saved state relights with), for comparison
  std::vector<std::uint8_t> synthesized;  // 1 where R was synthesized (texture_fill.h)
  std::vector<std::int32_t> object;       // what each pixel sees after the edits
  std::size_t synthesizedPixels = 0;
  double seconds = 0.0;
};

// `edited` is the recovered room's scene after the edits (the same objects in the same order,
// removed ones collapsed by scene::removeObject, inserted ones appended), `editedBvh` its BVH,
// `lamps` the lights (position, intensity, colour; no image).
RemodelledFrame renderRemodelled(const gpu::Context& context, const RecoveredRoom& room, const scene::Scene& edited,
                                 const bvh::Bvh& editedBvh, const scene::Camera& camera, const std::vector<Shot>& lamps,
                                 const RemodelOptions& options);

} // namespace obscura::recover
