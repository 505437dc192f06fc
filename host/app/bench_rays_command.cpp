// obscura bench-rays SCENE --rays N [--seed S] [--json] [--baseline embree] — traversal speed on
// the GPU path with reproducible rays (see bench/bench_rays.h), so other ray tracers can shoot the
// same ones. --baseline embree traces the same rays with Embree 3 in the same process (when built
// with it) and reports the ratio, which machine load affects on both sides alike.
#include <cstdio>
#include <cmath>
#include <optional>
#include <sys/resource.h>
#include <algorithm>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "scene/scene_edit.h"
#include "render/scene/scene_buffers.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "bench/bench_rays.h"
#ifdef OBSCURA_HAVE_EMBREE
#include "bench/embree_baseline.h"
#endif
#include "bench/ray_tracer.h"
#include "render/scene/scene_buffers.h"

namespace obscura::app {
namespace {

struct BenchOptions {
  std::string scenePath;
  std::size_t rays = 1u << 20;
  std::uint64_t seed = 1;
  int repeats = 3;
  std::size_t verify = 0;
  bool json = false;
  std::string saveRays;
  std::string baseline;
  std::string move;   // OBJECT=dx,dy,dz: move an object first (what a remodelling edit does)
  bool refit = false; // ...and refit the BVH instead of rebuilding it
  DeviceOptions device;
};

// Applies --move to the loaded scene and updates its BVH by refit or rebuild (traversal cost
// after an edit: a refit keeps the old topology, docs/BENCHMARKS.md).
void applyMove(const BenchOptions& o, LoadedScene& loaded) {
  const auto eq = o.move.rfind('=');
  glm::vec3 d(0.0f);
  if (eq == std::string::npos || std::sscanf(o.move.c_str() + eq + 1, "%f,%f,%f", &d.x, &d.y, &d.z) != 3)
    throw InputError(fmt::format("--move {}: expected OBJECT=dx,dy,dz", o.move));
  const std::size_t object = scene::objectIndex(loaded.scene, o.move.substr(0, eq), "--move");
  scene::moveObject(loaded.scene, object, d, glm::vec3(0.0f));
  if (o.refit) bvh::refit(loaded.bvh, render::triangleSoup(loaded.scene));
  else loaded.bvh = bvh::build(render::triangleSoup(loaded.scene));
}

// CPU time of the whole process (all threads), in ms. On lavapipe the "GPU" is this process's
// threads, so the CPU time of a trace is a measure that other load on the machine hardly affects.
double processCpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto ms = [](const timeval& t) { return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_usec) * 1e-3; };
  return ms(u.ru_utime) + ms(u.ru_stime);
}

struct SetResult {
  double bestMs = 0.0, medianMs = 0.0;
  double bestCpuMs = 0.0; // least process CPU time of one timed repeat
  double hitFraction = 0.0;
  double meanSteps = 0.0;
  // lavapipe runs 8 invocations (8 consecutive rays here) in lock-step: a group's loop runs as
  // long as its longest ray's. Mean of that maximum, and meanSteps / it = lane utilisation.
  double meanGroupMaxSteps = 0.0;
  std::size_t mismatches = 0;
};

SetResult runSet(render::RayTracer& tracer, const LoadedScene& loaded, const std::vector<gpu::GpuRay>& rays,
                 render::TraceMode mode, const BenchOptions& o) {
  SetResult r;
  // Warm-up (pipeline JIT, caches) and hit statistics, then timed repeats.
  auto first = tracer.trace(rays, mode, true);
  std::size_t hits = 0;
  double steps = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (first.hits[i].primitive != gpu::kInvalidIndex) ++hits;
    steps += first.steps[i];
  }
  r.hitFraction = rays.empty() ? 0.0 : static_cast<double>(hits) / static_cast<double>(rays.size());
  r.meanSteps = rays.empty() ? 0.0 : steps / static_cast<double>(rays.size());
  constexpr std::size_t kLanes = 8;
  double groupMax = 0.0;
  for (std::size_t g = 0; g < rays.size(); g += kLanes) {
    std::uint32_t m = 0;
    for (std::size_t i = g; i < std::min(rays.size(), g + kLanes); ++i) m = std::max(m, first.steps[i]);
    groupMax += m;
  }
  r.meanGroupMaxSteps = rays.empty() ? 0.0 : groupMax / static_cast<double>((rays.size() + kLanes - 1) / kLanes);
  std::vector<double> times, cpuMs;
  for (int k = 0; k < o.repeats; ++k) {
    double c0 = processCpuMs();
    times.push_back(tracer.trace(rays, mode).gpuMs);
    cpuMs.push_back(processCpuMs() - c0);
  }
  r.bestCpuMs = *std::min_element(cpuMs.begin(), cpuMs.end());
  std::sort(times.begin(), times.end());
  r.bestMs = times.front();
  r.medianMs = times[times.size() / 2];
  // Optional check of the first `verify` rays against the CPU reference traversal.
  for (std::size_t i = 0; i < std::min(o.verify, rays.size()); ++i) {
    bvh::Ray ray{glm::vec3(rays[i].origin), glm::vec3(rays[i].direction), rays[i].origin.w, rays[i].direction.w};
    bool gpuHit = first.hits[i].primitive != gpu::kInvalidIndex;
    if (mode == render::TraceMode::Closest) {
      bvh::Hit cpu = bvh::closestHit(loaded.bvh, ray);
      if (cpu.primitive != first.hits[i].primitive) ++r.mismatches;
    } else if (bvh::anyHit(loaded.bvh, ray) != gpuHit) {
      ++r.mismatches;
    }
  }
  return r;
}

// The baseline's figures beside ours, and the ratios ours / baseline.
struct Baseline {
  double buildSeconds = 0.0;
  double closestMrays = 0.0, shadowMrays = 0.0;
  double closestHitFraction = 0.0, shadowOccludedFraction = 0.0;
  double closestCpuMs = 0.0, shadowCpuMs = 0.0;
  unsigned threads = 0;
};

std::optional<Baseline> runBaseline(const BenchOptions& o, const LoadedScene& loaded,
                                    const std::vector<gpu::GpuRay>& closestRays,
                                    const std::vector<gpu::GpuRay>& shadowRays) {
  if (o.baseline.empty()) return std::nullopt;
#ifdef OBSCURA_HAVE_EMBREE
  auto e = render::runEmbreeBaseline(loaded.scene, closestRays, shadowRays, o.repeats);
  const double n = static_cast<double>(o.rays);
  return Baseline{.buildSeconds = e.buildSeconds,
                  .closestMrays = n / (e.closest.bestMs * 1e3),
                  .shadowMrays = n / (e.shadow.bestMs * 1e3),
                  .closestHitFraction = e.closest.hitFraction,
                  .shadowOccludedFraction = e.shadow.hitFraction,
                  .closestCpuMs = e.closest.bestCpuMs,
                  .shadowCpuMs = e.shadow.bestCpuMs,
                  .threads = e.threads};
#else
  (void)loaded;
  (void)closestRays;
  (void)shadowRays;
  throw InputError("--baseline embree: this obscura was built without Embree 3 "
                   "(install libembree-dev, e.g. tools/setup.sh, and re-run CMake)");
#endif
}

void runBench(const BenchOptions& o) {
  if (o.rays == 0) throw InputError("--rays must be at least 1");
#ifndef OBSCURA_HAVE_EMBREE
  if (!o.baseline.empty())
    throw InputError("--baseline embree: this obscura was built without Embree 3 "
                     "(install libembree-dev, e.g. tools/setup.sh, and re-run CMake)");
#endif
  LoadedScene loaded = loadScene(o.scenePath);
  if (!o.move.empty()) applyMove(o, loaded);
  gpu::Context context(o.device.contextOptions());
  if (!o.json) fmt::print("{}\ndevice: {} ({})\n", sceneSummary(loaded), context.info().name, context.info().driver);

  render::SceneBuffers buffers(context, loaded.scene, loaded.bvh);
  render::RayTracer tracer(context, buffers);
  auto closestRays = render::closestBenchRays(loaded.scene.bounds, o.rays, o.seed);
  auto shadowRays = render::shadowBenchRays(loaded.scene.bounds, o.rays, o.seed + 1);
  if (!o.saveRays.empty()) {
    render::saveRays(o.saveRays + ".closest.bin", closestRays);
    render::saveRays(o.saveRays + ".shadow.bin", shadowRays);
  }
  SetResult closest = runSet(tracer, loaded, closestRays, render::TraceMode::Closest, o);
  SetResult shadow = runSet(tracer, loaded, shadowRays, render::TraceMode::Any, o);
  std::optional<Baseline> base = runBaseline(o, loaded, closestRays, shadowRays);
  std::uint32_t truncated = buffers.truncatedTraversals();
  if (truncated > 0) throw DeviceError(fmt::format("{} traversals ran out of steps", truncated));
  if (closest.bestMs <= 0.0) throw DeviceError("the device has no timestamps; cannot time the traversal");

  const double n = static_cast<double>(o.rays);
  const double closestMrays = n / (closest.bestMs * 1e3), shadowMrays = n / (shadow.bestMs * 1e3);
  // The same rays must give the same answers (within 0.1%: Embree's own test is not watertight
  // and its shadow interval is closed at tmax, ours is open).
  bool baselineDisagrees = base && (std::abs(base->closestHitFraction - closest.hitFraction) > 1e-3 ||
                                    std::abs(base->shadowOccludedFraction - shadow.hitFraction) > 1e-3);
  if (o.json) {
    nlohmann::json j = {{"scene", loaded.scene.sourcePath}, {"device", context.info().name},
                        {"rays", o.rays}, {"seed", o.seed},
                        {"triangles", loaded.scene.triangles.size()},
                        {"build_s", loaded.bvh.stats.buildSeconds},
                        {"bvh_nodes", loaded.bvh.stats.nodeCount}, {"bvh_depth", loaded.bvh.stats.maxDepth},
                        {"sah_cost", loaded.bvh.stats.sahCost},
                        {"closest_mrays_per_s", closestMrays},
                        {"closest_median_mrays_per_s", n / (closest.medianMs * 1e3)},
                        {"closest_hit_fraction", closest.hitFraction},
                        {"closest_cpu_ms", closest.bestCpuMs},
                        {"shadow_cpu_ms", shadow.bestCpuMs},
                        {"closest_mean_steps", closest.meanSteps},
                        {"closest_mean_group_max_steps", closest.meanGroupMaxSteps},
                        {"shadow_mrays_per_s", shadowMrays},
                        {"shadow_median_mrays_per_s", n / (shadow.medianMs * 1e3)},
                        {"shadow_occluded_fraction", shadow.hitFraction},
                        {"shadow_mean_steps", shadow.meanSteps},
                        {"shadow_mean_group_max_steps", shadow.meanGroupMaxSteps},
                        {"verified", o.verify},
                        {"mismatches", closest.mismatches + shadow.mismatches}};
    if (base) {
      j["baseline"] = o.baseline;
      j["embree_threads"] = base->threads;
      j["embree_build_s"] = base->buildSeconds;
      j["embree_closest_mrays_per_s"] = base->closestMrays;
      j["embree_shadow_mrays_per_s"] = base->shadowMrays;
      j["embree_closest_hit_fraction"] = base->closestHitFraction;
      j["embree_shadow_occluded_fraction"] = base->shadowOccludedFraction;
      j["closest_ratio_vs_embree"] = closestMrays / base->closestMrays;
      j["shadow_ratio_vs_embree"] = shadowMrays / base->shadowMrays;
      // The same ratios from CPU time (embree / ours), which load on the machine hardly changes.
      j["embree_closest_cpu_ms"] = base->closestCpuMs;
      j["embree_shadow_cpu_ms"] = base->shadowCpuMs;
      j["closest_cpu_ratio_vs_embree"] = base->closestCpuMs / closest.bestCpuMs;
      j["shadow_cpu_ratio_vs_embree"] = base->shadowCpuMs / shadow.bestCpuMs;
    }
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("closest hit (a): {:8.2f} Mrays/s (best of {}, median {:.2f}), hit fraction {:.3f}, {:.1f} steps/ray "
               "({:.1f} per 8-ray group)\n",
               closestMrays, o.repeats, n / (closest.medianMs * 1e3), closest.hitFraction, closest.meanSteps,
               closest.meanGroupMaxSteps);
    fmt::print("shadow    (b): {:8.2f} Mrays/s (best of {}, median {:.2f}), occluded fraction {:.3f}, {:.1f} steps/ray "
               "({:.1f} per 8-ray group)\n",
               shadowMrays, o.repeats, n / (shadow.medianMs * 1e3), shadow.hitFraction, shadow.meanSteps,
               shadow.meanGroupMaxSteps);
    if (o.verify)
      fmt::print("verified the first {} rays of each set against the CPU: {} mismatches\n", o.verify,
                 closest.mismatches + shadow.mismatches);
    if (base) {
      fmt::print("embree {} threads: build {:.3f} s\n", base->threads, base->buildSeconds);
      fmt::print("  closest hit (a): {:8.2f} Mrays/s, hit fraction {:.3f}; ours / embree = {:.3f} "
                 "(by CPU time {:.3f})\n",
                 base->closestMrays, base->closestHitFraction, closestMrays / base->closestMrays,
                 base->closestCpuMs / closest.bestCpuMs);
      fmt::print("  shadow    (b): {:8.2f} Mrays/s, occluded fraction {:.3f}; ours / embree = {:.3f} "
                 "(by CPU time {:.3f})\n",
                 base->shadowMrays, base->shadowOccludedFraction, shadowMrays / base->shadowMrays,
                 base->shadowCpuMs / shadow.bestCpuMs);
    }
  }
  if (baselineDisagrees) throw DeviceError("the baseline's hit fractions differ from ours by more than 0.1%");
  if (closest.mismatches + shadow.mismatches > 0) throw DeviceError("GPU traversal disagrees with the CPU reference");
}

} // namespace

void addBenchRaysCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench-rays", "Measure BVH traversal (closest-hit and shadow rays) on the GPU path");
  cmd->add_option("scene", o->scenePath, "glTF 2.0 scene")->required();
  cmd->add_option("--rays", o->rays, "rays per set")->check(CLI::Range(std::size_t(1), std::size_t(1) << 26));
  cmd->add_option("--seed", o->seed, "seed of the ray generator");
  cmd->add_option("--repeats", o->repeats, "timed repeats per set (the best is reported)")->check(CLI::Range(1, 100));
  cmd->add_option("--verify", o->verify, "check the first N rays of each set against the CPU traversal");
  cmd->add_option("--save-rays", o->saveRays, "write the rays to PREFIX.closest.bin / PREFIX.shadow.bin");
  cmd->add_option("--baseline", o->baseline, "also trace the same rays with this ray tracer and print the ratio")
      ->check(CLI::IsMember({"embree"}));
  cmd->add_flag("--json", o->json, "print one JSON line");
  cmd->add_option("--move", o->move, "OBJECT=dx,dy,dz: move an object first, then rebuild the BVH (or --refit)");
  cmd->add_flag("--refit", o->refit, "with --move: refit the BVH (the topology of before the move) instead of a rebuild");
  addDeviceOptions(*cmd, o->device);
  cmd->callback([o] { runBench(*o); });
}

} // namespace obscura::app
