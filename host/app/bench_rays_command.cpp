// obscura bench-rays SCENE --rays N [--seed S] [--json] [--baseline embree] — traversal speed on
// the GPU path with reproducible rays (see bench/bench_rays.h), so other ray tracers can shoot the
// same ones. --baseline embree traces the same rays with Embree 3 in the same process (when built
// with it) and reports the ratio, which machine load affects on both sides alike.
// --passes WxH adds a real render of the paper's budget: each pass's rays per second (the
// renderer's counters and GPU timestamps) beside the rate of its kind of ray above, and the
// frame's wall and GPU time. --frame WxH (repeatable) adds the obscurance-only frame traced by
// Obscura and by Embree in the same process (bench/pass_bench.h, bench/embree_frame.h).
#include <cstdio>
#include <cmath>
#include <optional>
#include <algorithm>
#include <array>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "scene/scene_edit.h"
#include "render/scene_data/scene_buffers.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "bench/bench_rays.h"
#ifdef OBSCURA_HAVE_EMBREE
#include "bench/embree_baseline.h"
#include "bench/embree_frame.h"
#endif
#include "bench/lane_order.h"
#include "bench/pass_bench.h"
#include "bench/ray_set_measurement.h"
#include "render/ray_tracer.h"
#include "render/passes/primary_pass.h"
#include "app/render_options.h"

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
  std::string passes;              // WxH: the paper's budget rendered, per pass
  std::vector<std::string> frames; // WxH each: the obscurance-only frame, Obscura against Embree
  std::string lanes;               // WxH: lane utilisation of that frame's rays in several orders
  std::string traceShape;          // WxR: trace.comp's workgroup size and rays per invocation
  std::optional<std::uint32_t> stackRegisters; // the kernel's compact-stack registers (0: the general kernel)
  std::string bvhItems = "texel";              // how trace.comp reads the BVH: "texel" view or "storage" buffer
  bool cullOnPop = false;                      // the binary traversal with its cull on pop
  std::optional<float> spatialSplits; // the tree's spatial splits (bvh::BuildOptions::spatialSplitBudget); unset: the device's tree
  bench::ObscuranceFrameWork frameWork; // its spp, rays per hit, dmax, seed
  DeviceOptions device;
};

// "800x600" -> {800, 600}; InputError naming the option otherwise.
glm::uvec2 parseSize(const std::string& text, const char* option) {
  unsigned w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%ux%u%c", &w, &h, &tail) != 2 || w == 0 || h == 0 || w > 16384 || h > 16384)
    throw InputError(fmt::format("{} {}: expected WIDTHxHEIGHT, e.g. 800x600 (1 to 16384 each)", option, text));
  return {w, h};
}

// --trace-shape WxR: trace.comp's workgroup size W (a multiple of 8, lavapipe's SIMD width) and
// rays per invocation R (1 to kTraceRaysPerLane), for trying other shapes on a new device.
render::TraceShape parseTraceShape(const std::string& text, const gpu::Context& context) {
  unsigned w = 0, r = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%ux%u%c", &w, &r, &tail) != 2 || w == 0 || w % 8 != 0 || w > 1024 || r == 0 ||
      r > gpu::kTraceRaysPerLane)
    throw InputError(fmt::format("--trace-shape {}: expected WORKGROUPxRAYS, a workgroup of 8 to 1024 invocations "
                                 "(a multiple of 8) and 1 to {} rays per invocation, e.g. 128x1",
                                 text, gpu::kTraceRaysPerLane));
  // trace.comp keeps 12 bytes of hit and steps per ray in shared memory.
  if (w > context.info().maxComputeWorkGroupInvocations || std::size_t(w) * r * 12 > 32768)
    throw InputError(fmt::format("--trace-shape {}: {} invocations of {} rays need {} bytes of shared memory "
                                 "(at most 32768, and {} invocations)",
                                 text, w, r, std::size_t(w) * r * 12, context.info().maxComputeWorkGroupInvocations));
  return {w, r};
}

// The tree --spatial-splits asks for, else the one the device's traversal is fastest on.
bvh::BuildOptions treeOptions(const BenchOptions& o, const gpu::Context& context) {
  bvh::BuildOptions options = render::treeOptionsFor(render::traversalFor(context));
  if (o.spatialSplits) options.spatialSplitBudget = *o.spatialSplits;
  return options;
}

// Applies --move to the loaded scene and updates its BVH by refit or rebuild (traversal cost
// after an edit: a refit keeps the old topology, docs/BENCHMARKS.md).
void applyMove(const BenchOptions& o, LoadedScene& loaded, const gpu::Context& context) {
  const auto eq = o.move.rfind('=');
  glm::vec3 d(0.0f);
  if (eq == std::string::npos || std::sscanf(o.move.c_str() + eq + 1, "%f,%f,%f", &d.x, &d.y, &d.z) != 3)
    throw InputError(fmt::format("--move {}: expected OBJECT=dx,dy,dz", o.move));
  const std::size_t object = scene::objectIndex(loaded.scene, o.move.substr(0, eq), "--move");
  scene::moveObject(loaded.scene, object, d, glm::vec3(0.0f));
  if (o.refit) bvh::refit(loaded.bvh, render::triangleSoup(loaded.scene));
  else loaded.bvh = bvh::build(render::triangleSoup(loaded.scene), treeOptions(o, context));
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
  auto e = bench::runEmbreeBaseline(loaded.scene, closestRays, shadowRays, o.repeats);
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

// --passes: the paper's budget rendered at one size, each pass beside the bench-rays rate of the
// kind of ray it traces (primary, obscurance and specular rays: closest hit; shadow rays: any hit).
struct PassesRun {
  glm::uvec2 size{0};
  render::RenderStats stats;
};

const char* benchKindOf(const std::string& pass) { return pass == "shadow" ? "shadow" : "closest"; }

#ifdef OBSCURA_HAVE_EMBREE
// --frame: one size of the obscurance-only frame, by Obscura and by Embree (a build without
// Embree refuses --frame before it gets here).
struct FrameRun {
  glm::uvec2 size{0};
  bench::ObscuraFrameResult ours;
  bench::EmbreeFrameResult embree;
};

double meanOf(const std::vector<float>& values) {
  double sum = 0.0;
  for (float v : values) sum += v;
  return values.empty() ? 0.0 : sum / static_cast<double>(values.size());
}

FrameRun runFrame(const BenchOptions& o, const gpu::Context& context, const LoadedScene& loaded,
                  const scene::Camera& camera, glm::uvec2 size) {
  FrameRun run;
  run.size = size;
  bench::ObscuranceFrameWork work = o.frameWork;
  work.width = size.x;
  work.height = size.y;
  work.camera = render::gpuCamera(camera, size.x, size.y);
  work.sceneScale = render::sceneScale(loaded.scene.bounds);
  run.ours = bench::runObscuraFrame(context, loaded.scene, loaded.bvh, camera, work, o.repeats);
  run.embree = bench::runEmbreeFrame(loaded.scene, work, o.repeats);
  // The same work on both sides: every camera ray, and N_obs rays per hit (the hits may differ at
  // a few silhouette pixels: Embree's triangle test is not watertight, ours is).
  if (run.ours.primaryRays != run.embree.primaryRays)
    throw DeviceError(fmt::format("--frame {}x{}: {} camera rays traced by Obscura, {} by Embree", size.x, size.y,
                                  run.ours.primaryRays, run.embree.primaryRays));
  const double a = static_cast<double>(run.ours.obscuranceRays), b = static_cast<double>(run.embree.obscuranceRays);
  if (std::abs(a - b) > 1e-2 * std::max(a, b))
    throw DeviceError(fmt::format("--frame {}x{}: {} obscurance rays by Obscura, {} by Embree (more than 1% apart)",
                                  size.x, size.y, run.ours.obscuranceRays, run.embree.obscuranceRays));
  return run;
}
#endif

nlohmann::json passesJson(const PassesRun& p, double closestMrays, double shadowMrays) {
  nlohmann::json passes = nlohmann::json::object();
  for (const auto& [name, pass] : p.stats.passes) {
    nlohmann::json j = {{"gpu_ms", pass.gpuMs}, {"rays", pass.rays}};
    if (pass.rays > 0 && pass.gpuMs > 0.0) {
      const double mrays = static_cast<double>(pass.rays) / (pass.gpuMs * 1e3);
      const char* kind = benchKindOf(name);
      j["mrays_per_s"] = mrays;
      j["bench_rays_kind"] = kind;
      j["ratio_vs_bench_rays"] = mrays / (std::string(kind) == "shadow" ? shadowMrays : closestMrays);
    }
    passes[name] = j;
  }
  return {{"width", p.size.x}, {"height", p.size.y}, {"wall_s", p.stats.wallSeconds},
          {"gpu_ms", p.stats.totalGpuMs()}, {"per_pass", passes}};
}

#ifdef OBSCURA_HAVE_EMBREE
nlohmann::json frameJson(const BenchOptions& o, const FrameRun& f) {
  return {{"width", f.size.x}, {"height", f.size.y}, {"spp", o.frameWork.spp},
          {"obscurance_rays_per_hit", o.frameWork.obscuranceRays}, {"dmax", o.frameWork.dMax},
          {"obscura_gpu_ms", f.ours.bestMs}, {"obscura_median_gpu_ms", f.ours.medianMs},
          {"obscura_primary_ms", f.ours.bestPrimaryMs}, {"obscura_obscurance_ms", f.ours.bestObscuranceMs},
          {"obscura_cpu_ms", f.ours.bestCpuMs},
          {"obscura_primary_rays", f.ours.primaryRays}, {"obscura_obscurance_rays", f.ours.obscuranceRays},
          {"obscura_mean_obscurance", meanOf(f.ours.obscurance)},
          {"embree_threads", f.embree.threads}, {"embree_ms", f.embree.bestMs},
          {"embree_median_ms", f.embree.medianMs}, {"embree_cpu_ms", f.embree.bestCpuMs},
          {"embree_primary_rays", f.embree.primaryRays}, {"embree_obscurance_rays", f.embree.obscuranceRays},
          {"embree_obscurance_rays_traced", f.embree.obscuranceRaysTraced},
          {"embree_mean_obscurance", meanOf(f.embree.obscurance)},
          {"ratio_vs_embree", f.embree.bestMs / f.ours.bestMs},
          {"cpu_ratio_vs_embree", f.embree.bestCpuMs / f.ours.bestCpuMs}};
}
#endif

void printPasses(const PassesRun& p, double closestMrays, double shadowMrays) {
  const render::ObscuranceSettings budget;
  fmt::print("passes: the paper's budget at {}x{} ({} spp, {} shadow + {} obscurance rays per hit{}; the image alone, "
             "as render -o out.png makes it), best repeat by GPU time: wall {:.2f} s, GPU {:.0f} ms\n",
             p.size.x, p.size.y, render::kPaperSpp, render::kPaperShadowRays, render::kPaperObscuranceRays,
             budget.vertexRaysByThroughput ? ", at specular path vertices scaled by throughput" : "",
             p.stats.wallSeconds, p.stats.totalGpuMs());
  fmt::print("  {:<12} {:>10} {:>12} {:>9}   {}\n", "pass", "GPU ms", "rays", "Mrays/s",
             "/ bench-rays rate of its kind (goal >= 0.77, i.e. within 1.3x)");
  for (const auto& [name, pass] : p.stats.passes) {
    if (pass.rays == 0 || pass.gpuMs <= 0.0) {
      fmt::print("  {:<12} {:>10.1f}\n", name, pass.gpuMs);
      continue;
    }
    const double mrays = static_cast<double>(pass.rays) / (pass.gpuMs * 1e3);
    const std::string kind = benchKindOf(name);
    fmt::print("  {:<12} {:>10.1f} {:>12} {:>9.2f}   {:.2f} of {} ({:.2f} Mrays/s)\n", name, pass.gpuMs, pass.rays,
               mrays, mrays / (kind == "shadow" ? shadowMrays : closestMrays), kind,
               kind == "shadow" ? shadowMrays : closestMrays);
  }
}

#ifdef OBSCURA_HAVE_EMBREE
void printFrame(const BenchOptions& o, const FrameRun& f) {
  fmt::print("frame {}x{}: obscurance only, {} spp x {} rays, dmax {} (best of {})\n", f.size.x, f.size.y,
             o.frameWork.spp, o.frameWork.obscuranceRays, o.frameWork.dMax, o.repeats);
  fmt::print("  obscura: primary {:.1f} ms + obscurance {:.1f} ms = {:.1f} ms GPU (process CPU {:.0f} ms); {} camera + "
             "{} obscurance rays, mean W {:.4f}\n",
             f.ours.bestPrimaryMs, f.ours.bestObscuranceMs, f.ours.bestMs, f.ours.bestCpuMs, f.ours.primaryRays,
             f.ours.obscuranceRays, meanOf(f.ours.obscurance));
  fmt::print("  embree {} threads: {:.1f} ms (process CPU {:.0f} ms); {} camera + {} obscurance rays ({} traced), "
             "mean W {:.4f}\n",
             f.embree.threads, f.embree.bestMs, f.embree.bestCpuMs, f.embree.primaryRays, f.embree.obscuranceRays,
             f.embree.obscuranceRaysTraced, meanOf(f.embree.obscurance));
  fmt::print("  ours / embree = {:.3f} (by CPU time {:.3f})\n", f.embree.bestMs / f.ours.bestMs,
             f.embree.bestCpuMs / f.ours.bestCpuMs);
}
#endif

void runBench(const BenchOptions& o) {
  if (o.rays == 0) throw InputError("--rays must be at least 1");
#ifndef OBSCURA_HAVE_EMBREE
  if (!o.baseline.empty())
    throw InputError("--baseline embree: this obscura was built without Embree 3 "
                     "(install libembree-dev, e.g. tools/setup.sh, and re-run CMake)");
#endif
  if (!o.frames.empty() && o.baseline != "embree")
    throw InputError("--frame compares Obscura with Embree on the same frame: add --baseline embree");
  std::optional<glm::uvec2> passesSize;
  if (!o.passes.empty()) passesSize = parseSize(o.passes, "--passes");
  std::optional<glm::uvec2> lanesSize;
  if (!o.lanes.empty()) lanesSize = parseSize(o.lanes, "--lanes");
  std::vector<glm::uvec2> frameSizes;
  for (const auto& f : o.frames) frameSizes.push_back(parseSize(f, "--frame"));
  if (!(std::isfinite(o.frameWork.dMax) && o.frameWork.dMax > 0.0f))
    throw InputError(fmt::format("--frame-dmax {}: must be a finite positive distance in scene units", o.frameWork.dMax));
  LoadedScene loaded = loadScene(o.scenePath, "node", std::nullopt);
  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.device);
  const gpu::Context& context = *contextHandle;
  loaded.bvh = bvh::build(render::triangleSoup(loaded.scene), treeOptions(o, context));
  if (!o.move.empty()) applyMove(o, loaded, context);
  if (!o.json) fmt::print("{}\ndevice: {} ({})\n", sceneSummary(loaded), context.info().name, context.info().driver);

  render::SceneBuffers buffers(context, loaded.scene, loaded.bvh);
  for (const std::string& note : buffers.notes()) fmt::print(stderr, "note: {}\n", note);
  if (!o.json) fmt::print("traversal: {}\n", render::traversalName(buffers.traversal()));
  std::optional<render::TraceShape> shape;
  if (!o.traceShape.empty()) shape = parseTraceShape(o.traceShape, context);
  if (o.bvhItems == "storage" || o.cullOnPop) {
    if (!shape) shape = render::TraceShape::forDevice(context, buffers.traversal());
    shape->bvhItemsFromStorage = o.bvhItems == "storage";
    shape->binaryCullOnPop = o.cullOnPop;
  }
  if (o.stackRegisters && !bvh::compactStackHolds(*o.stackRegisters, buffers.compactStackVectors()))
    throw InputError(fmt::format("--stack-registers {}: this BVH (depth {}) needs {} (or 0, the general kernel)",
                                 *o.stackRegisters, loaded.bvh.stats.maxDepth, buffers.compactStackVectors()));
  render::RayTracer tracer(context, buffers, shape, o.stackRegisters);
  auto closestRays = bench::closestBenchRays(loaded.scene.bounds, o.rays, o.seed);
  auto shadowRays = bench::shadowBenchRays(loaded.scene.bounds, o.rays, o.seed + 1);
  if (!o.saveRays.empty()) {
    bench::saveRays(o.saveRays + ".closest.bin", closestRays);
    bench::saveRays(o.saveRays + ".shadow.bin", shadowRays);
  }
  const bool backToBack = context.info().type != "cpu";
  const bench::RaySetOptions setOptions{.repeats = o.repeats, .verify = o.verify, .backToBack = backToBack};
  const bench::RaySetMeasurement closest =
      bench::measureRaySet(tracer, loaded.scene, loaded.bvh, closestRays, render::TraceMode::Closest, setOptions);
  const bench::RaySetMeasurement shadow =
      bench::measureRaySet(tracer, loaded.scene, loaded.bvh, shadowRays, render::TraceMode::Any, setOptions);
  std::optional<Baseline> base = runBaseline(o, loaded, closestRays, shadowRays);
  const scene::Camera camera = chooseCamera(loaded.scene, -1);
  std::optional<PassesRun> passes;
  if (passesSize)
    passes = PassesRun{*passesSize, bench::renderPaperBudget(context, loaded.scene, loaded.bvh, camera, passesSize->x,
                                                              passesSize->y, o.repeats)};
#ifdef OBSCURA_HAVE_EMBREE
  std::vector<FrameRun> frames;
  for (glm::uvec2 size : frameSizes) frames.push_back(runFrame(o, context, loaded, camera, size));
#endif
  std::vector<bench::LaneOrderFigures> lanes;
  if (lanesSize) {
    bench::ObscuranceFrameWork work = o.frameWork;
    work.width = lanesSize->x;
    work.height = lanesSize->y;
    work.camera = render::gpuCamera(camera, work.width, work.height);
    work.sceneScale = render::sceneScale(loaded.scene.bounds);
    lanes = bench::measureLaneOrders(tracer, loaded.scene, work, o.repeats);
  }
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
                        {"traversal", render::traversalName(buffers.traversal())},
                        {"trace_workgroup_size", tracer.shape().workgroupSize},
                        {"trace_rays_per_invocation", tracer.shape().raysPerLane},
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
                        {"mismatches", closest.mismatches + shadow.mismatches},
                        {"float_precision_differences", closest.precisionDifferences + shadow.precisionDifferences}};
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
    if (passes) j["passes"] = passesJson(*passes, closestMrays, shadowMrays);
#ifdef OBSCURA_HAVE_EMBREE
    for (const FrameRun& f : frames) j["frames"].push_back(frameJson(o, f));
#endif
    for (const auto& l : lanes)
      j["lanes"].push_back({{"order", l.name}, {"rays", l.rays}, {"mean_steps", l.meanSteps},
                            {"group_steps", l.groupSteps}, {"utilisation", l.utilisation()}, {"gpu_ms", l.gpuMs}});
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("trace.comp: workgroups of {}, {} ray(s) per invocation\n", tracer.shape().workgroupSize,
               tracer.shape().raysPerLane);
    fmt::print("closest hit (a): {:8.2f} Mrays/s (best of {}, median {:.2f}), hit fraction {:.3f}, {:.1f} steps/ray "
               "({:.1f} as 8-lane groups run them)\n",
               closestMrays, o.repeats, n / (closest.medianMs * 1e3), closest.hitFraction, closest.meanSteps,
               closest.meanGroupMaxSteps);
    fmt::print("shadow    (b): {:8.2f} Mrays/s (best of {}, median {:.2f}), occluded fraction {:.3f}, {:.1f} steps/ray "
               "({:.1f} as 8-lane groups run them)\n",
               shadowMrays, o.repeats, n / (shadow.medianMs * 1e3), shadow.hitFraction, shadow.meanSteps,
               shadow.meanGroupMaxSteps);
    if (o.verify)
      fmt::print("verified the first {} rays of each set against the CPU: {} mismatches ({} more differ only as float "
                 "rounding may: a grazed edge, a tie in t, a hit at the ray's end)\n",
                 o.verify, closest.mismatches + shadow.mismatches,
                 closest.precisionDifferences + shadow.precisionDifferences);
    for (const bench::RaySetMeasurement* set : {&closest, &shadow})
      for (const std::string& example : set->mismatchExamples) fmt::print("  mismatch: {}\n", example);
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
    if (passes) printPasses(*passes, closestMrays, shadowMrays);
#ifdef OBSCURA_HAVE_EMBREE
    for (const FrameRun& f : frames) printFrame(o, f);
#endif
    if (lanesSize)
      fmt::print("lanes: sample 0 of the obscurance-only frame at {}x{}, traced by trace.comp in each order\n",
                 lanesSize->x, lanesSize->y);
    for (const auto& l : lanes)
      fmt::print("  {:<52} {:>9} rays {:6.2f} steps/ray {:6.2f} per group  utilisation {:5.1f} %  {:8.1f} ms "
                 "({:.2f} Mrays/s)\n",
                 l.name, l.rays, l.meanSteps, l.groupSteps, 100.0 * l.utilisation(), l.gpuMs,
                 static_cast<double>(l.rays) / (l.gpuMs * 1e3));
  }
  if (baselineDisagrees) throw DeviceError("the baseline's hit fractions differ from ours by more than 0.1%");
  if (closest.mismatches + shadow.mismatches > 0) throw DeviceError("GPU traversal disagrees with the CPU reference");
  // Rounding explains a grazed edge or a tie now and then (Sponza: 0.4 % of 1M rays), not a
  // share beyond 1 %: a kernel that stored no hit for most rays once passed as "rounding".
  const std::size_t verified = 2 * std::min(o.verify, static_cast<std::size_t>(o.rays));
  if (closest.precisionDifferences + shadow.precisionDifferences > std::max<std::size_t>(10, verified / 100))
    throw DeviceError(fmt::format("{} of {} verified rays differ from the CPU reference (more than rounding explains)",
                                  closest.precisionDifferences + shadow.precisionDifferences, verified));
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
  cmd->add_option("--passes", o->passes,
                  "WxH: also render the paper's budget at this size and print each pass's rays per second beside "
                  "the rate of its kind of ray");
  cmd->add_option("--frame", o->frames,
                  "WxH (repeatable): also trace the obscurance-only frame at this size with Obscura and with Embree "
                  "(needs --baseline embree) and print the ratio");
  cmd->add_option("--lanes", o->lanes,
                  "WxH: lane utilisation (loop passes per ray over those per 8-lane group) of the obscurance-only "
                  "frame's rays at this size, in the passes' order and coherent ones");
  cmd->add_option("--trace-shape", o->traceShape,
                  fmt::format("WORKGROUPxRAYS: trace.comp's workgroup size and rays per invocation (default: "
                              "{}x{} on a CPU device, {}x{} on a GPU)",
                              gpu::kTraceWorkgroupSize, gpu::kTraceRaysPerLane, gpu::kTraceGpuWorkgroupSize,
                              gpu::kTraceGpuRaysPerLane));
  cmd->add_option("--stack-registers", o->stackRegisters,
                  fmt::format("trace.comp's traversal stack in this many uvec4 registers (1 to {}, at least what the "
                              "BVH needs), or 0 for the general kernel's stack in memory (default: what the BVH needs)",
                              gpu::kBvhCompactStackVectors))
      ->check(CLI::Range(0u, gpu::kBvhCompactStackVectors));
  cmd->add_option("--bvh-items", o->bvhItems,
                  "how trace.comp reads the BVH's nodes and triangles: through the texel view the passes use "
                  "(texel, the default) or from the same buffer bound as an SSBO (storage)")
      ->check(CLI::IsMember({"texel", "storage"}));
  cmd->add_flag("--cull-on-pop", o->cullOnPop,
                "the binary traversal's closest-hit rays drop popped children beyond their hit (off in the passes)");
  cmd->add_option("--spatial-splits", o->spatialSplits,
                  "SHARE: build the BVH with spatial splits (SBVH), adding at most this share of the triangle "
                  "count as clipped references (default: the tree the renderer builds for the device's traversal, "
                  "none for the wide layout, 0.1 for the binary one)")
      ->check(CLI::Range(0.0f, 4.0f));
  cmd->add_option("--frame-spp", o->frameWork.spp, "--frame: samples per pixel")->check(CLI::Range(1u, 1024u));
  cmd->add_option("--frame-rays", o->frameWork.obscuranceRays, "--frame: obscurance rays per hit")
      ->check(CLI::Range(1u, 256u));
  cmd->add_option("--frame-dmax", o->frameWork.dMax, "--frame: dmax in scene units");
  addDeviceOptions(*cmd, o->device);
  cmd->callback([o] { runBench(*o); });
}

} // namespace obscura::app
