// obscura converge SCENE -o DIR — speed against error [SPEC §4]. Renders converged references
// (cached as EXR in DIR, each with a .txt naming the command and settings that made it), then
// each method at increasing sample counts, recording GPU time and the error against (a) the
// converged obscurance image (noise) and (b) converged path tracing (bias + noise), in RMSE and in
// two robust measures (image_error.h). Writes a CSV, a log-log plot (tools/plot_convergence.py),
// the obscurance image at the paper's budget beside path tracing at equal GPU time (PNG), and
// prints for each obscurance method: the equal-noise speed-up over path tracing, the error
// against converged path tracing against time, the bias floor, and the crossover time after
// which path tracing's error is lower. The renders and references are analysis::ConvergenceStudy's
// (analysis/convergence_study.h), the figures analysis/convergence.h's; this file reads the
// options and writes the report.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <filesystem>
#include <memory>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/named_option.h"
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "analysis/convergence.h"
#include "analysis/convergence_study.h"
#include "analysis/image_error.h"
#include "render/method.h"
#include "render/obscurance_renderer.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

// The study's settings and the device's.
struct ConvergeOptions : analysis::StudySettings {
  DeviceOptions device;
};

// A measured noise within this factor of its reference's own noise says more about the reference
// than about the method (measured^2 = own^2 + the reference's^2 for independent errors: at 2x, a
// quarter of the measured variance is the reference's): such a point is named, not used.
constexpr double kReferenceFloorFactor = 2.0;

// The reference's own noise in `metric`, 0 where not known.
double floorOf(const analysis::ImageError* own, analysis::Metric metric) {
  return own ? analysis::errorOf(*own, metric) : 0.0;
}

// `curve` without the points whose noise (in `metric`) is within kReferenceFloorFactor of
// `floor`: what a speed-up may be read from.
analysis::Curve aboveFloor(const analysis::Curve& curve, double floor, analysis::Metric metric) {
  analysis::Curve kept{.method = curve.method, .points = {}};
  for (const auto& p : curve.points)
    if (analysis::errorOf(p, analysis::ErrorKind::Noise, metric) >= kReferenceFloorFactor * floor) kept.points.push_back(p);
  return kept;
}

void runConverge(const ConvergeOptions& o) {
  checkBackground(o.background);
  LoadedScene loaded = loadScene(o.scenePath, "node", std::nullopt); // first: a bad scene leaves no folder behind
  if (!o.background.empty()) loaded.scene.background = glm::vec3(o.background[0], o.background[1], o.background[2]);
  std::error_code ec;
  fs::create_directories(o.outputDir, ec);
  if (ec || !fs::is_directory(o.outputDir))
    throw InputError(fmt::format("{}: cannot create the output folder{}", o.outputDir, ec ? ": " + ec.message() : ""));
  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.device);
  const gpu::Context& context = *contextHandle;
  buildTreeFor(loaded, context);
  fmt::print("{}\ndevice: {} ({})\n", sceneSummary(loaded), context.info().name, context.info().driver);
  warnIfUnlit(loaded);
  analysis::ConvergenceStudy study(o, loaded.scene, loaded.bvh, context);

  const std::vector<analysis::StudyMethod> methods = analysis::studyMethods(o);
  const analysis::StudyMethod& best = methods.front();
  const analysis::StudyMethod& pathMethod = methods.back();
  const io::Image obscuranceReference = study.reference(best);
  const io::Image ptReference = study.reference(pathMethod);
  // Secondary reflectors converge to an image of their own: their noise is measured against it.
  std::map<std::string, io::Image> reflectorReferences;
  for (const analysis::StudyMethod& m : methods)
    if (m.secondaryReflectors > 0.0f) reflectorReferences[m.name] = study.reference(m);
  // A frame corrected by paths converges to path tracing's image: its noise is measured against that.
  auto noiseReference = [&](const analysis::StudyMethod& m, std::uint32_t spp) -> const io::Image& {
    if (m.pathTrace || m.correctionPaths(spp) > 0) return ptReference;
    return m.secondaryReflectors > 0.0f ? reflectorReferences.at(m.name) : obscuranceReference;
  };
  // How converged each reference is (the difference of its two halves): noise measured against it
  // cannot fall below that.
  auto noiseFloor = [&](const analysis::StudyMethod& m, std::uint32_t spp) {
    return study.referenceNoise(m.pathTrace || m.correctionPaths(spp) > 0 ? pathMethod.name
                                : m.secondaryReflectors > 0.0f ? m.name
                                                               : best.name);
  };
  nlohmann::json referenceNoiseJson = nlohmann::json::object();
  for (const analysis::StudyMethod* m : {&best, &pathMethod}) {
    const analysis::ImageError* own = noiseFloor(*m, 1);
    if (!own) {
      fmt::print("reference {}: its own noise is not known (a single image); speed-ups are read without a floor\n",
                 m->name);
      continue;
    }
    fmt::print("reference {}: own noise (from its two halves) RMSE {:.5f}, trimmed RMSE {:.5f}, MAE {:.5f}; noise "
               "within {:g}x of it is not measured\n",
               m->name, own->rmse, own->rmseTrimmed, own->mae, kReferenceFloorFactor);
    referenceNoiseJson[m->name == best.name ? "obscurance" : "pathtrace"] = {
        {"rmse", own->rmse}, {"rmse_trimmed", own->rmseTrimmed}, {"mae", own->mae}};
  }

  std::vector<analysis::Curve> curves;
  std::map<std::string, io::Image> atBudget; // each method's image at its budget
  const fs::path csvPath = fs::path(o.outputDir) / (study.stem() + ".convergence.csv");
  std::ofstream csv(csvPath);
  csv << "method,spp,rays_per_pixel,gpu_ms,rmse_noise,relmse_noise,mae_noise,rmse_trimmed_noise,"
         "rmse_vs_pathtrace,relmse_vs_pathtrace,mae_vs_pathtrace,rmse_trimmed_vs_pathtrace,noise_at_reference_floor\n";
  for (const auto& m : methods) {
    analysis::Curve curve{.method = m.name, .points = {}};
    std::uint32_t maxSpp = m.pathTrace ? o.pathMaxSpp : o.obscuranceMaxSpp;
    for (std::uint32_t spp = 1; spp <= maxSpp; spp *= 2) {
      analysis::StudyRender r = study.render(m, spp, o.seed + spp);
      analysis::CurvePoint p{.spp = spp, .raysPerPixel = r.rays, .gpuMs = r.gpuMs,
                           .noise = analysis::imageError(r.image, noiseReference(m, spp)),
                           .total = analysis::imageError(r.image, ptReference)};
      if (spp == m.budgetSpp) atBudget[m.name] = r.image;
      curve.points.push_back(p);
      // Which measures of its noise are within kReferenceFloorFactor of the reference's own.
      std::string atFloor;
      for (const auto& [key, metric] : {std::pair{"rmse", analysis::Metric::Rmse},
                                        std::pair{"trimmed", analysis::Metric::RmseTrimmed}, std::pair{"mae", analysis::Metric::Mae}})
        if (analysis::errorOf(p, analysis::ErrorKind::Noise, metric) <
            kReferenceFloorFactor * floorOf(noiseFloor(m, spp), metric))
          atFloor += atFloor.empty() ? key : std::string("+") + key;
      csv << fmt::format("{},{},{:.2f},{:.3f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{}\n", m.name, spp,
                         p.raysPerPixel, p.gpuMs, p.noise.rmse, p.noise.relMse, p.noise.mae, p.noise.rmseTrimmed,
                         p.total.rmse, p.total.relMse, p.total.mae, p.total.rmseTrimmed, atFloor);
      fmt::print("{:20s} spp {:4d}  {:7.1f} rays/px  {:9.1f} ms  noise RMSE {:.5f} (trimmed {:.5f}, MAE {:.5f})  "
                 "vs PT RMSE {:.5f}{}\n",
                 m.name, spp, p.raysPerPixel, p.gpuMs, p.noise.rmse, p.noise.rmseTrimmed, p.noise.mae, p.total.rmse,
                 atFloor.empty() ? "" : "  [at the reference's floor: " + atFloor + "]");
      std::fflush(stdout);
    }
    curves.push_back(curve);
  }
  csv.close();

  const analysis::Curve& pt = curves.back();
  nlohmann::json summary = {{"scene", o.scenePath}, {"width", study.width()}, {"height", study.height()},
                            {"device", context.info().name}, {"command", o.commandLine},
                            {"reference_noise", referenceNoiseJson}, {"reference_floor_factor", kReferenceFloorFactor}};
  auto errorJson = [](const analysis::ImageError& e) {
    return nlohmann::json{{"rmse", e.rmse}, {"relmse", e.relMse}, {"mae", e.mae}, {"rmse_trimmed", e.rmseTrimmed},
                          {"mean_ratio", e.meanRatio}};
  };
  const analysis::ImageError bias = analysis::imageError(obscuranceReference, ptReference);
  const analysis::TimeAt ptBelowFloor = analysis::timeToReach(pt, bias.rmse, analysis::ErrorKind::AgainstReference);
  fmt::print("\nbias floor (converged obscurance, seen I_a, vs converged path tracing): RMSE {:.5f}, relMSE {:.5f}, "
             "MAE {:.5f}, trimmed RMSE {:.5f}, mean ratio {:.4f}\n",
             bias.rmse, bias.relMse, bias.mae, bias.rmseTrimmed, bias.meanRatio);
  fmt::print("crossover: path tracing's error falls below that floor after {:.1f} ms{}\n", ptBelowFloor.ms,
             ptBelowFloor.extrapolated ? " (extrapolated)" : "");
  summary["bias_floor"] = errorJson(bias);
  for (const auto& [model, what] : {std::pair{"reached", "the reached I_a"}, std::pair{"global", "the paper's whole-scene I_a"}}) {
    const analysis::ImageError e = analysis::imageError(study.otherReference(model, best.name), ptReference);
    fmt::print("bias floor with {}: RMSE {:.5f}, relMSE {:.5f}, MAE {:.5f}, trimmed RMSE {:.5f}, mean ratio {:.4f}\n", what,
               e.rmse, e.relMse, e.mae, e.rmseTrimmed, e.meanRatio);
    summary[fmt::format("bias_floor_{}_ia", model)] = errorJson(e);
  }
  for (const auto& [name, reference] : reflectorReferences) {
    const analysis::ImageError seen = analysis::imageError(reference, ptReference);
    const analysis::ImageError reached = analysis::imageError(study.otherReference("reached", name), ptReference);
    const analysis::ImageError global = analysis::imageError(study.otherReference("global", name), ptReference);
    for (const auto& [which, e] :
         {std::pair{"seen I_a", seen}, std::pair{"reached I_a", reached}, std::pair{"the paper's I_a", global}})
      fmt::print("bias floor with secondary reflectors ({}), {}: RMSE {:.5f}, relMSE {:.5f}, MAE {:.5f}, trimmed RMSE "
                 "{:.5f}, mean ratio {:.4f}\n",
                 name, which, e.rmse, e.relMse, e.mae, e.rmseTrimmed, e.meanRatio);
    summary["bias_floor_" + name] = errorJson(seen);
    summary["bias_floor_" + name + "_reached_ia"] = errorJson(reached);
    summary["bias_floor_" + name + "_global_ia"] = errorJson(global);
  }
  summary["crossover_ms"] = ptBelowFloor.ms;
  summary["crossover_extrapolated"] = ptBelowFloor.extrapolated;

  // Per obscurance method at its budget: equal-noise speed-up in each measure, and the time path
  // tracing needs to reach the same total error (bias included).
  const std::pair<const char*, analysis::Metric> metrics[] = {
      {"rmse", analysis::Metric::Rmse}, {"rmse_trimmed", analysis::Metric::RmseTrimmed}, {"mae", analysis::Metric::Mae}};
  for (std::size_t i = 0; i + 1 < methods.size(); ++i) {
    const analysis::StudyMethod& m = methods[i];
    const analysis::CurvePoint* point = nullptr;
    for (const auto& p : curves[i].points)
      if (p.spp == m.budgetSpp) point = &p;
    if (!point) continue;
    nlohmann::json entry = {{"what", m.what}, {"spp", point->spp}, {"gpu_ms", point->gpuMs},
                            {"rays_per_pixel", point->raysPerPixel}};
    fmt::print("\n{} ({}): {:.1f} ms, {:.1f} rays per pixel\n", m.name, m.what, point->gpuMs, point->raysPerPixel);
    for (const auto& [key, metric] : metrics) {
      const double noise = analysis::errorOf(*point, analysis::ErrorKind::Noise, metric);
      const double total = analysis::errorOf(*point, analysis::ErrorKind::AgainstReference, metric);
      const double floor = floorOf(noiseFloor(m, point->spp), metric), ptFloor = floorOf(noiseFloor(pathMethod, 1), metric);
      if (noise < kReferenceFloorFactor * floor) {
        // A flat curve is named, not read: the reference is not converged enough to tell.
        fmt::print("  {:13s} noise {:.5f} is within {:g}x of its reference's own noise {:.5f}: no speed-up is read "
                   "(render a more converged reference: --reference-factor)\n",
                   key, noise, kReferenceFloorFactor, floor);
        entry[key] = {{"noise", noise}, {"at_reference_floor", true}, {"reference_noise", floor},
                      {"total_error", total}};
        continue;
      }
      // Path tracing's curve where it is above its own reference's floor (beyond, extrapolated).
      const analysis::Curve ptAbove = aboveFloor(pt, ptFloor, metric);
      if (ptAbove.points.empty()) {
        fmt::print("  {:13s} path tracing's noise is at its reference's own noise at every point: no speed-up is read "
                   "(--pt-reference-spp)\n",
                   key);
        entry[key] = {{"noise", noise}, {"pathtrace_at_reference_floor", true}, {"total_error", total}};
        continue;
      }
      const analysis::TimeAt equalNoise = analysis::timeToReach(ptAbove, noise, analysis::ErrorKind::Noise, metric);
      const analysis::TimeAt equalTotal = analysis::timeToReach(pt, total, analysis::ErrorKind::AgainstReference, metric);
      const double speedUp = equalNoise.valid ? equalNoise.ms / point->gpuMs : 0.0;
      fmt::print("  {:13s} noise {:.5f}: path tracing reaches it in {:9.1f} ms{} -> equal-noise speed-up {:.2f}x; "
                 "total error {:.5f}: path tracing reaches it in {:.1f} ms{}\n",
                 key, noise, equalNoise.ms, equalNoise.extrapolated ? " (extrap.)" : "", speedUp, total, equalTotal.ms,
                 equalTotal.extrapolated ? " (extrap.)" : "");
      entry[key] = {{"noise", noise}, {"pathtrace_ms_to_equal_noise", equalNoise.ms},
                    {"equal_noise_extrapolated", equalNoise.extrapolated}, {"equal_noise_speedup", speedUp},
                    {"total_error", total}, {"pathtrace_ms_to_equal_total_error", equalTotal.ms},
                    {"equal_total_extrapolated", equalTotal.extrapolated}};
    }
    // Total error (bias and noise) against path tracing's at the same GPU time, at every point of the
    // curve (path tracing's curve read there, log-log; past its last point extrapolated): where the
    // method is worth its bias. A ratio above 1 says path tracing is nearer the truth by then.
    {
      double worst = 0.0, worstMs = 0.0;
      bool extrapolated = false;
      for (const auto& p : curves[i].points) {
        const analysis::ErrorAt ptThen = analysis::errorAtTime(pt, p.gpuMs, analysis::ErrorKind::AgainstReference,
                                                               analysis::Metric::Rmse);
        if (ptThen.error <= 0.0) continue;
        const double ratio = p.total.rmse / ptThen.error;
        if (ratio > worst) {
          worst = ratio;
          worstMs = p.gpuMs;
          extrapolated = ptThen.extrapolated;
        }
      }
      const double lastMs = curves[i].points.empty() ? 0.0 : curves[i].points.back().gpuMs;
      fmt::print("  total error against path tracing's at equal time, worst over the curve (to {:.0f} ms): {:.3f} at "
                 "{:.1f} ms{} ({})\n",
                 lastMs, worst, worstMs, extrapolated ? " (path tracing extrap.)" : "",
                 worst <= 1.0 ? "below path tracing's at every point" : "path tracing is nearer there");
      entry["worst_total_error_ratio_at_equal_time"] = {{"ratio", worst}, {"gpu_ms", worstMs}, {"curve_to_ms", lastMs},
                                                        {"pathtrace_extrapolated", extrapolated}};
    }
    // A denoised frame against the same rays undenoised at the same GPU time (its curve read there):
    // what the denoiser's time buys, in RMSE against the converged reference (noise and bias alike).
    if (m.denoise) {
      const std::string plain = m.name.substr(0, m.name.rfind("-denoised"));
      for (std::size_t j = 0; j + 1 < methods.size(); ++j) {
        if (methods[j].name != plain) continue;
        const analysis::ErrorAt undenoised =
            analysis::errorAtTime(curves[j], point->gpuMs, analysis::ErrorKind::Noise, analysis::Metric::Rmse);
        const double denoised = point->noise.rmse;
        fmt::print("  at equal time ({:.1f} ms), {} undenoised has RMSE {:.5f}{}: the denoised frame's {:.5f} is {}\n",
                   point->gpuMs, plain, undenoised.error, undenoised.extrapolated ? " (extrap.)" : "", denoised,
                   denoised <= undenoised.error ? "lower" : "HIGHER (the denoiser loses)");
        entry["undenoised_at_equal_time"] = {{"method", plain}, {"rmse", undenoised.error},
                                             {"extrapolated", undenoised.extrapolated},
                                             {"denoised_wins", denoised <= undenoised.error}};
      }
    }
    summary["methods"][m.name] = entry;
  }

  // What a user sees: the obscurance image at the paper's budget and path tracing at equal GPU time.
  if (atBudget.contains(best.name)) {
    const analysis::CurvePoint* point = nullptr;
    for (const auto& p : curves.front().points)
      if (p.spp == best.budgetSpp) point = &p;
    const double msPerPath = pt.points.back().gpuMs / pt.points.back().spp;
    const auto ptSpp = static_cast<std::uint32_t>(std::max(1.0, std::round(point->gpuMs / msPerPath)));
    analysis::StudyRender equalTime = study.render(pathMethod, ptSpp, o.seed + 104729);
    const fs::path obsPng = fs::path(o.outputDir) / (study.stem() + ".obscurance-budget.png");
    const fs::path ptPng = fs::path(o.outputDir) / (study.stem() + ".pathtrace-equal-time.png");
    io::writePng(obsPng.string(), atBudget.at(best.name), atBudget.at(best.name).channelIndex("combined.R"));
    io::writePng(ptPng.string(), equalTime.image, equalTime.image.channelIndex("combined.R"));
    fmt::print("\nequal time: obscurance {} spp in {:.1f} ms -> {}; path tracing {} spp in {:.1f} ms -> {}\n",
               best.budgetSpp, point->gpuMs, obsPng.string(), ptSpp, equalTime.gpuMs, ptPng.string());
    summary["equal_time_pngs"] = {{"obscurance", obsPng.string()}, {"pathtrace", ptPng.string()},
                                  {"pathtrace_spp", ptSpp}, {"pathtrace_gpu_ms", equalTime.gpuMs}};
  }
  const fs::path jsonPath = fs::path(o.outputDir) / (study.stem() + ".convergence.json");
  std::ofstream(jsonPath) << summary.dump(2) << "\n";

  const fs::path plotPath = fs::path(o.outputDir) / (study.stem() + ".convergence.png");
  std::string plot = fmt::format("/usr/bin/python3 {}/tools/plot_convergence.py '{}' '{}' '{}' '{}'", OBSCURA_SOURCE_DIR,
                                 csvPath.string(), plotPath.string(), study.stem(), jsonPath.string());
  if (std::system(plot.c_str()) != 0)
    throw InputError(fmt::format("{}: the plot failed (python3-matplotlib installed? see tools/setup.sh)", plotPath.string()));
  fmt::print("wrote {}, {}, {}\n", csvPath.string(), plotPath.string(), jsonPath.string());
}

} // namespace

void addConvergeCommand(CLI::App& app) {
  auto o = std::make_shared<ConvergeOptions>();
  CLI::App* cmd = app.add_subcommand("converge", "Speed against error: obscurances vs path tracing (CSV, plot, summary)");
  cmd->add_option("scene", o->scenePath, "glTF 2.0 scene")->required();
  cmd->add_option("-o,--output", o->outputDir, "folder for references, CSV, plot and summary")->required();
  cmd->add_option("--width", o->width, "image width (height from the camera's aspect)")->check(CLI::Range(8u, 4096u));
  cmd->add_option("--max-spp", o->obscuranceMaxSpp, "largest obscurance sample count (powers of 2 up to it; default 32: past 8 spp the defaults' "
                  "frames are corrected by paths, as render's, and reach past a second of GPU time)")
      ->check(CLI::Range(8u, 4096u));
  cmd->add_option("--pt-max-spp", o->pathMaxSpp, "largest path-tracing sample count")->check(CLI::Range(1u, 1u << 20));
  cmd->add_option("--reference-factor", o->referenceFactor, "reference spp = factor x largest curve spp (>= 64 per SPEC)")
      ->check(CLI::Range(1u, 4096u));
  cmd->add_option("--pt-reference-spp", o->pathReferenceSpp, "path-tracing reference spp (default: factor x --pt-max-spp)");
  cmd->add_option("--pt-reference", o->pathReferenceFile,
                  "a merged farm render to use as the path-tracing reference instead of rendering it (obscura merge's "
                  "EXR of 'render --method pathtrace --width W' parts of this scene; tools/farm/)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", o->seed, "seed");
  cmd->add_option("--dmax", o->dMax, "obscurance dmax (default: the renderer's, half the median free path)")
      ->check(CLI::PositiveNumber);
  addNamedOption(*cmd, "--escapes", o->escapes, render::kEscapeModelNames,
                 "obscurance rays that leave the scene: auto, dark or ambient (as render's; default auto)");
  cmd->add_option("--background", o->background, "R,G,B: a constant sky for both methods (as render --background)")
      ->delimiter(',')
      ->expected(3);
  addEmissionSamplesOption(*cmd, "--emission-samples", o->emissionSamples, o->emissionAtEdges,
                           "the obscurance methods, as render's");
  addEmissionSamplesOption(*cmd, "--pt-emission-samples", o->pathEmissionSamples, o->pathEmissionAtEdges,
                           "path tracing");
  cmd->add_option("--secondary-reflectors", o->secondaryReflectors,
                  "T: study obscurances with secondary reflectors marked at T x mean direct irradiance too "
                  "(method obscurance-reflectors, with its own reference and bias floor)")
      ->check(CLI::PositiveNumber);
  addDeviceOptions(*cmd, o->device);
  cmd->callback([o, cmd] {
    o->commandLine = "obscura converge";
    for (const auto* opt : cmd->get_options()) {
      if (opt->count() == 0 || opt->get_name().empty()) continue;
      const bool positional = opt->get_lnames().empty() && opt->get_snames().empty();
      o->commandLine += (positional ? " " : " " + opt->get_name() + " ") + opt->as<std::string>();
    }
    runConverge(*o);
  });
}

} // namespace obscura::app
