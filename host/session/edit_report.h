// edit_report.h — what one edit cost and changed (EditSession::apply): one line of
// `relight --edits`' edits.jsonl, the window's frame log and status line, and what a Python
// caller or a benchmark reads.
#pragma once
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "render/obscurance_renderer.h"
#include "session/scene_history.h"

namespace obscura::session {

struct EditReport {
  std::string kind;                           // Edit::kindName()
  std::string name;                           // the light or object edited
  std::uint64_t pixelsRetraced = 0;           // pixels whose rays were traced again
  std::map<std::string, std::uint64_t> rays;  // per pass, traced by the edit
  std::map<std::string, double> gpuMs;        // per pass, GPU time of the edit
  std::optional<BvhUpdate> bvh;               // geometry edits: how the BVH followed
  // What the lights reach (the Reached ambient model's rays, traced on the device), measured
  // again: geometry edits and added lights.
  std::optional<render::ObscuranceRenderer::ReachUpdate> reach;
  double totalMs = 0.0;                       // wall time, edit to composed frame when composed
  // Host work: the wall time not spent in the GPU passes above (BVH update, the reach's CPU
  // rays not hidden behind GPU work, bookkeeping, submission and waits).
  double hostMs() const;
  // Host CPU time of the edit on every thread it used (core/host_cpu_time.h), whether or not it
  // overlapped GPU work: what an edit on a GPU waits for. lavapipe's own threads (the device's
  // work there) are not in it.
  double cpuMs = 0.0;

  // Adds the per-pass rays and GPU ms between two of a renderer's counters.
  void addPasses(const render::RenderStats& before, const render::RenderStats& after);
  // One line of edits.jsonl: kind, name, pixels_retraced, rays, gpu_ms, bvh, reach, host_ms,
  // cpu_ms, total_ms.
  nlohmann::json json() const;
};

} // namespace obscura::session
