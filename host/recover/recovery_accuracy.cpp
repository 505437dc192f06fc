// recovery_accuracy.cpp — see recovery_accuracy.h.
#include "recover/recovery_accuracy.h"

#include <algorithm>
#include <cmath>

namespace obscura::recover {

std::vector<LightRegion> lightRegions(const std::vector<ConfidenceImage>& visibility, const std::vector<std::int32_t>& object) {
  std::vector<LightRegion> regions(object.size(), LightRegion::None);
  std::vector<ConfidenceImage> widened;
  for (const auto& v : visibility) widened.push_back(minFilter(v, 2));
  for (std::size_t p = 0; p < object.size(); ++p) {
    if (object[p] < 0) continue;
    float lit = 0.0f, any = 0.0f;
    for (std::size_t i = 0; i < visibility.size(); ++i) {
      lit = std::max(lit, widened[i].k[p]);
      any = std::max(any, visibility[i].k[p]);
    }
    regions[p] = lit >= 0.999f ? LightRegion::Lit : any <= 0.001f ? LightRegion::Shadow : LightRegion::Penumbra;
  }
  return regions;
}

RecoveryAccuracy recoveryAccuracy(const std::vector<glm::vec3>& recovered, const std::vector<glm::vec3>& truth,
                                  const std::vector<LightRegion>& regions) {
  struct Sum {
    double squares = 0.0;
    std::size_t pixels = 0;
    void add(double e) { squares += e; ++pixels; }
    RegionError error() const { return {pixels > 0 ? std::sqrt(squares / (3.0 * double(pixels))) : 0.0, pixels}; }
  } lit, penumbra, shadow, all, direct;
  for (std::size_t p = 0; p < regions.size(); ++p) {
    if (regions[p] == LightRegion::None) continue;
    const glm::vec3 d = recovered[p] - truth[p];
    const double e = glm::dot(d, d);
    all.add(e);
    (regions[p] == LightRegion::Lit ? lit : regions[p] == LightRegion::Penumbra ? penumbra : shadow).add(e);
    if (regions[p] != LightRegion::Shadow) direct.add(e);
  }
  return {lit.error(), penumbra.error(), shadow.error(), all.error(), direct.error()};
}

} // namespace obscura::recover
