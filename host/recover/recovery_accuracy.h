// recovery_accuracy.h — how far a recovered reflectance is from a known one (synthetic
// photographs' answer key), in the regions the lamps define:
//   lit        some photo lights the pixel and its whole 5x5 neighbourhood (max over photos of
//              the 5x5 min of V_i is 1): the paper's filters leave it full confidence
//   penumbra   some photo lights it, but each only near a shadow edge
//   shadow     no photo lights it (every V_i = 0): only indirect light, the fill's pixels
// The regions depend on the visibilities alone, so variants of the filters compare on the same
// pixels. Pixels that see no surface are left out.
#pragma once
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "recover/confidence_filters.h"

namespace obscura::recover {

struct RegionError {
  double rmse = 0.0;     // over the region's pixels and the three channels
  std::size_t pixels = 0;
};

struct RecoveryAccuracy {
  RegionError lit, penumbra, shadow, all;
  RegionError direct; // lit or penumbra: some photo lights the pixel directly
};

enum class LightRegion : unsigned char { None, Lit, Penumbra, Shadow };

// The region of every pixel (None where `object` is -1).
std::vector<LightRegion> lightRegions(const std::vector<ConfidenceImage>& visibility, const std::vector<std::int32_t>& object);

RecoveryAccuracy recoveryAccuracy(const std::vector<glm::vec3>& recovered, const std::vector<glm::vec3>& truth,
                                  const std::vector<LightRegion>& regions);

} // namespace obscura::recover
