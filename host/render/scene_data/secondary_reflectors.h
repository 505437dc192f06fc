// secondary_reflectors.h — important secondary reflectors, the obscurance paper's answer to "a lamp
// pointed at a wall, or sunlight on a red carpet" [RTO §2.2] made concrete as its future work
// proposes [RTO §6, SPEC §1.6]: "take account of the patches touched by a high-energy direct light
// ray ... if an obscurance ray hits one of them, an additional ray to the light is traced".
//
// Marking (OURS, the paper leaves the test open): triangle t is marked when, for some light s, the
// light rays of ReachedSurfaces give it a direct irradiance of at least `threshold` times the mean
// irradiance that light spreads over everything it reaches:
//   (rays landed on t / A_t) >= threshold x (rays landed / A_s).
// The test is scale-free in every emission, so relighting never changes what is marked.
//
// Combining (OURS): at a marked Q the obscurance ray adds Q's reflected direct light, traced, and
// the ambient there keeps only the share kappa of I_a beyond the first bounce:
//   kappa = 1 - 1 / S,  S = sum_{j=1}^{d-1} R_ave^(j-1)  (1 / (1 - R_ave) for the paper's series)
// per channel, with the render's R_ave and path depth, so the first bounce is not counted twice.
// An unmarked Q keeps I_a's later bounces and its first bounce scaled by r, the direct irradiance
// of the unmarked surfaces against the mean of all: the marked ones hold more than their share of
// the light, so the rest hold less. Per light s, with f_s its landed rays on marked triangles and
// a_s the marked share of the area it reaches, r_s = (1 - f_s) / (1 - a_s); r is their mean over
// the lights (unweighted: it must not change when a light is dimmed). Unmarked share:
//   kappa + r (1 - kappa).
// Both are constants of the render (like R_ave), so I_a stays linear in every emission.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/scene_data/reached_surfaces.h"
#include "scene/scene.h"

namespace obscura::render {

struct SecondaryReflectorMarks {
  std::vector<std::uint8_t> marked; // per triangle of the scene, 1 = marked
  std::uint32_t count = 0;          // triangles marked
  float unmarkedFirstBounce = 1.0f; // r above
};

// `reach` holds one entry per light (zero area falls back to `totalArea`, as does every light when
// `reachedAreas` is false: the paper's I_a spreads the flux over the whole scene). Triangles the
// light rays never landed on are not marked.
SecondaryReflectorMarks markSecondaryReflectors(const scene::Scene& scene, const std::vector<LightReach>& reach,
                                                double threshold, double totalArea, bool reachedAreas = true);

// kappa above; `depth` 0 = the whole series.
glm::vec3 ambientShareBeyondFirstBounce(glm::vec3 averageReflectance, std::uint32_t depth);

} // namespace obscura::render
