#include "session/edit_report.h"

#include <algorithm>

namespace obscura::session {

double EditReport::hostMs() const {
  double gpu = 0.0;
  for (const auto& [pass, ms] : gpuMs) gpu += ms;
  return std::max(0.0, totalMs - gpu);
}

void EditReport::addPasses(const render::RenderStats& before, const render::RenderStats& after) {
  for (const auto& [passName, pass] : after.passes) {
    const auto it = before.passes.find(passName);
    const double ms = pass.gpuMs - (it == before.passes.end() ? 0.0 : it->second.gpuMs);
    const auto n = pass.rays - (it == before.passes.end() ? 0 : it->second.rays);
    if (ms <= 0.0 && n == 0) continue;
    rays[passName] += n;
    gpuMs[passName] += ms;
  }
}

nlohmann::json EditReport::json() const {
  nlohmann::json line = {{"kind", kind},
                         {"name", name},
                         {"pixels_retraced", pixelsRetraced},
                         {"rays", rays},
                         {"gpu_ms", gpuMs},
                         {"host_ms", hostMs()},
                         {"cpu_ms", cpuMs},
                         {"total_ms", totalMs}};
  if (bvh) {
    const bool refit = bvh->kind == BvhUpdate::Kind::Refit;
    line["bvh"] = {{"kind", refit ? "refit" : bvh->kind == BvhUpdate::Kind::Insert ? "insert" : "rebuild"}, {"ms", bvh->ms}};
    if (refit) line["bvh"]["nodes"] = bvh->nodes;
  }
  if (reach) line["reach"] = {{"rays", reach->rays}, {"ms", reach->ms}};
  return line;
}

} // namespace obscura::session
