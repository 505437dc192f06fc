// obscura converge SCENE -o DIR — speed against error [SPEC §4]. Renders converged references
// (cached as EXR in DIR, each with a .txt naming the command and settings that made it), then
// each method at increasing sample counts, recording GPU time and the error against (a) the
// converged obscurance image (noise) and (b) converged path tracing (bias + noise), in RMSE and in
// two robust measures (image_error.h). Writes a CSV, a log-log plot (tools/plot_convergence.py),
// the obscurance image at the paper's budget beside path tracing at equal GPU time (PNG), and
// prints for each obscurance method: the equal-noise speed-up over path tracing, the error
// against converged path tracing against time, the bias floor, and the crossover time after
// which path tracing's error is lower.
//
// Every obscurance method estimates the same image (ray counts and light sampling change the
// noise, not the expectation), so one converged obscurance render, made with the best
// estimators, is the noise reference of all of them. The denoised methods (render/denoise/) are
// measured the same way: one frame denoised alone, its GPU time counted.
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
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "farm/merge.h"
#include "io/image_io.h"
#include "analysis/convergence.h"
#include "analysis/image_error.h"
#include "render/denoise/denoiser.h"
#include "render/method.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

// The default emission rays per sample: the primary ray alone. They pay where bright emitters seen
// directly set the error (the Cornell box: --emission-samples 16 --pt-emission-samples 4) and cost
// more than they remove where the emitters are small on screen (modern-hall); docs/BENCHMARKS.md,
// "Emission rays and the split of shading rays".
constexpr std::uint32_t kObscuranceEmissionSamples = 1, kPathEmissionSamples = 1;

struct ConvergeOptions {
  std::string scenePath;
  std::string outputDir;
  std::uint32_t width = 256; // per-pixel noise as a user sees it
  std::uint32_t obscuranceMaxSpp = 16;
  std::uint32_t pathMaxSpp = 256;
  std::uint32_t referenceFactor = 64;   // a reference has this many times the largest curve's spp
  std::uint32_t pathReferenceSpp = 0;   // 0: referenceFactor x pathMaxSpp
  // A merged farm render (`obscura merge`'s EXR of --method pathtrace parts) to take as the path
  // tracing reference instead of rendering it here: the longest render of a study, spread over a
  // cluster (tools/farm/).
  std::string pathReferenceFile;
  std::uint32_t seed = 1;
  float dMax = 0.0f; // 0: the renderer's default
  float secondaryReflectors = 0.0f; // > 0: one more method, obscurances with secondary reflectors
  std::vector<float> background;    // R,G,B of a sky (render --background); empty: none
  // Camera rays per sample for the emission the camera sees (render --emission-samples), each
  // method family with the count that serves it best (docs/BENCHMARKS.md).
  std::uint32_t emissionSamples = kObscuranceEmissionSamples;
  std::uint32_t pathEmissionSamples = kPathEmissionSamples;
  std::string commandLine;
  DeviceOptions device;
};

struct Method {
  std::string name;
  bool pathTrace = false;
  render::LightSampling lightSampling = render::LightSampling::Spatial;
  std::uint32_t raysPerHit = 5;   // shadow (and obscurance, see below) rays per hit (obscurance methods)
  std::uint32_t budgetSpp = 8;    // the budget its summary is read at
  std::string what;
  float secondaryReflectors = 0.0f; // their marking threshold, 0 = off
  bool denoise = false;             // the frame denoised (render/denoise/), its GPU time counted
  std::uint32_t obscuranceRays = 0; // obscurance rays per hit; 0: raysPerHit
  std::uint32_t emissionSamples = 0; // camera rays per sample for the seen emission; 0: the study's
  bool vertexRaysByThroughput = true; // specular path vertices: rays scaled by throughput, or N per hit
};

// The paper's budget [RTO §4.1]: 8 primary samples x (5 obscurance + 5 shadow rays) per hit.
constexpr std::uint32_t kPaperSpp = 8, kPaperRays = 5;

// Each method with its best estimators, the paper's estimator for reproduction, and a real-time
// budget (one primary sample with 1 + 1 rays per hit). Path tracing comes last.
const std::vector<Method> kMethods = {
    {"obscurance", false, render::LightSampling::Spatial, kPaperRays, kPaperSpp,
     "spatial light sampling, 5+5 rays per hit, 8 spp (the paper's budget)"},
    {"obscurance-paper", false, render::LightSampling::Area, kPaperRays, kPaperSpp,
     "the paper's light sampling (by power, by area), 5+5 rays per hit, 8 spp"},
    // The same 10 shading rays per hit, spent where modern-hall's noise is: its direct light
    // holds 2/3 of the variance at 5 + 5, the obscurance 2 % (docs/BENCHMARKS.md).
    {"obscurance-split", false, render::LightSampling::Spatial, 8, kPaperSpp,
     "spatial light sampling, 8 shadow + 2 obscurance rays per hit, 8 spp", 0.0f, false, 2},
    // What scaling a specular path vertex's rays by its throughput (the default) saves and costs.
    {"obscurance-per-hit-vertices", false, render::LightSampling::Spatial, kPaperRays, kPaperSpp,
     "as obscurance, 5+5 rays at every specular path vertex too (render --vertex-rays per-hit)", 0.0f, false, 0, 0,
     false},
    {"obscurance-realtime", false, render::LightSampling::Spatial, 1, 1, "spatial, 1+1 rays per hit, 1 spp"},
    // The window's frames: the same, denoised (one frame alone, no history), error measured.
    {"obscurance-denoised", false, render::LightSampling::Spatial, kPaperRays, 1,
     "spatial, 5+5 rays per hit, denoised (a-trous on demodulated terms), 1 spp", 0.0f, true},
    {"obscurance-realtime-denoised", false, render::LightSampling::Spatial, 1, 1,
     "spatial, 1+1 rays per hit, denoised, 1 spp", 0.0f, true},
    {"pathtrace", true, render::LightSampling::Spatial, 0, 1, "path tracing, NEE with spatial light sampling + MIS"},
};

// The methods a study runs: kMethods, and with --secondary-reflectors the best obscurance method
// with them too (before path tracing, which stays last).
std::vector<Method> studyMethods(const ConvergeOptions& o) {
  std::vector<Method> methods = kMethods;
  if (o.secondaryReflectors > 0.0f) {
    Method m = methods.front();
    m.name = "obscurance-reflectors";
    m.what = fmt::format("as obscurance, with secondary reflectors marked at {:g} x mean direct irradiance",
                         o.secondaryReflectors);
    m.secondaryReflectors = o.secondaryReflectors;
    methods.insert(methods.end() - 1, m);
  }
  if (o.emissionSamples > 1) { // what the emission rays change, in the same run
    Method m = methods.front();
    m.name = "obscurance-primary-emission";
    m.what = "as obscurance, the seen emission from the primary rays alone (--emission-samples 1)";
    m.emissionSamples = 1;
    methods.insert(methods.begin() + 1, m);
  }
  return methods;
}

struct Rendered {
  io::Image image;
  double gpuMs = 0.0;
  double rays = 0.0;
};

class Study {
public:
  Study(const ConvergeOptions& o, const LoadedScene& loaded, const gpu::Context& context)
      : o_(o), loaded_(loaded), context_(context) {
    camera_ = loaded.scene.cameras.empty() ? scene::defaultCamera(loaded.scene.bounds) : loaded.scene.cameras.front();
    float aspect = camera_.aspectRatio > 0.0f ? camera_.aspectRatio : 1.0f;
    width_ = o.width;
    height_ = std::max(1u, static_cast<std::uint32_t>(std::lround(static_cast<float>(o.width) / aspect)));
    stem_ = fs::path(o.scenePath).stem().string();
    // Checked before anything is rendered: a wrong reference fails the study at once.
    if (!o.pathReferenceFile.empty()) farmReference_ = farmReference();
  }

  // Renders with the study's persistent renderers: the scene is uploaded and the pipelines are
  // made once per method family, not once per render.
  Rendered render(const Method& m, std::uint32_t spp, std::uint32_t seed) {
    Rendered r;
    const render::RenderStats* stats = nullptr;
    if (m.pathTrace) {
      render::PathTraceSettings s{.width = width_, .height = height_, .spp = spp, .seed = seed, .camera = camera_,
                                  .lightSampling = m.lightSampling, .emissionSamples = o_.pathEmissionSamples};
      if (!pathTracer_) pathTracer_ = std::make_unique<render::PathTracer>(context_, loaded_.scene, loaded_.bvh, s);
      pathTracer_->configure(s);
      pathTracer_->render();
      r.image = pathTracer_->image();
      statsCopy_ = pathTracer_->stats();
    } else {
      render::ObscuranceSettings s;
      s.editableGeometry = false;
      s.width = width_;
      s.height = height_;
      s.spp = spp;
      s.emissionSamples = m.emissionSamples ? m.emissionSamples : o_.emissionSamples;
      s.seed = seed;
      s.camera = camera_;
      s.shadowRays = m.raysPerHit;
      s.obscuranceRays = m.obscuranceRays ? m.obscuranceRays : m.raysPerHit;
      s.lightSampling = m.lightSampling;
      s.ambient = render::AmbientModel::Seen; // the least biased I_a; Reached and Global composed beside it
      s.dMax = o_.dMax;
      s.secondaryReflectors = m.secondaryReflectors;
      s.vertexRaysByThroughput = m.vertexRaysByThroughput;
      if (!obscurance_)
        obscurance_ = std::make_unique<render::ObscuranceRenderer>(context_, loaded_.scene, loaded_.bvh, s);
      obscurance_->configure(s);
      obscurance_->render();
      r.image = obscurance_->image();
      statsCopy_ = obscurance_->stats();
      if (m.denoise) {
        if (!denoiser_) denoiser_ = std::make_unique<render::Denoiser>(context_, *obscurance_);
        denoiser_->reset(); // each render is a frame of its own
        denoiser_->denoise(*obscurance_);
        r.image = denoiser_->image();
        r.gpuMs += denoiser_->lastGpuMs();
      }
    }
    stats = &statsCopy_;
    if (stats->truncatedTraversals) throw DeviceError("traversals were truncated; the study would be wrong");
    for (const auto& [name, pass] : stats->passes) {
      r.gpuMs += pass.gpuMs;
      r.rays += static_cast<double>(pass.rays);
    }
    r.rays /= static_cast<double>(width_) * height_;
    return r;
  }

  // The path tracing reference from a merged farm render, checked to be of this study's image:
  // the same scene (hash), camera, size, depth and sky.
  io::Image farmReference() const {
    const std::string& file = o_.pathReferenceFile;
    const io::Image image = io::readImage(file);
    const std::string* text = image.attribute(farm::kMergedAttribute);
    if (!text) throw InputError(fmt::format("{}: not a merged farm render (no {} attribute; 'obscura merge' writes it)",
                                            file, farm::kMergedAttribute));
    const nlohmann::json job = nlohmann::json::parse(*text, nullptr, false);
    auto mismatch = [&](const std::string& what, const nlohmann::json& theirs, const nlohmann::json& ours) {
      return InputError(fmt::format("{}: a reference of another image: its {} is {}, this study's {}", file, what,
                                    theirs.dump(), ours.dump()));
    };
    if (!job.is_object() || !job.contains("method")) throw InputError(fmt::format("{}: its job description is malformed", file));
    const std::string pathTrace = nameString(render::kMethodNames, render::Method::PathTrace);
    if (job.at("method") != pathTrace) throw mismatch("method", job.at("method"), pathTrace);
    if (job.at("scene") != farm::sceneHash(o_.scenePath)) throw mismatch("scene", job.at("scene"), o_.scenePath);
    if (job.at("width") != width_ || job.at("height") != height_)
      throw mismatch("size", {job.at("width"), job.at("height")}, {width_, height_});
    if (job.at("camera") != -1) throw mismatch("camera", job.at("camera"), -1);
    if (job.at("max_depth") != render::PathTraceSettings{}.maxDepth)
      throw mismatch("max depth", job.at("max_depth"), render::PathTraceSettings{}.maxDepth);
    if (job.at("background") != nlohmann::json(o_.background)) throw mismatch("background", job.at("background"), o_.background);
    if (image.channelIndex("combined.R") < 0) throw InputError(fmt::format("{}: no combined channels", file));
    fmt::print("reference pathtrace: the farm render {} ({} spp)\n", file, job.at("spp").dump());
    return combinedOnly(image);
  }

  // The converged image of a method, from the cache when the same settings made it.
  io::Image reference(const Method& m) {
    if (m.pathTrace && !o_.pathReferenceFile.empty()) return farmReference_;
    std::uint32_t spp = m.pathTrace ? (o_.pathReferenceSpp ? o_.pathReferenceSpp : o_.referenceFactor * o_.pathMaxSpp)
                                    : o_.referenceFactor * o_.obscuranceMaxSpp;
    fs::path exr = fs::path(o_.outputDir) / fmt::format("{}.{}.reference.exr", stem_, m.name);
    fs::path txt = exr;
    txt.replace_extension(".txt");
    std::string description = fmt::format("scene={} method={} width={} height={} spp={} seed={} rays_per_hit={} "
                                          "emission_samples={} light_sampling={}{}{}",
                                          o_.scenePath, m.name, width_, height_, spp, o_.seed + 7919, m.raysPerHit,
                                          m.pathTrace ? o_.pathEmissionSamples : o_.emissionSamples,
                                          nameOf(render::kLightSamplingNames, m.lightSampling),
                                          m.pathTrace ? "" : fmt::format(" ambient=seen+reached+global dmax={} secondary_reflectors={}",
                                                                         o_.dMax, m.secondaryReflectors),
                                          o_.background.empty() ? "" : fmt::format(" background={}", fmt::join(o_.background, ",")));
    if (fs::exists(exr) && fs::exists(txt)) {
      std::ifstream in(txt);
      std::string first;
      std::getline(in, first);
      if (first == description &&
          (m.pathTrace || (fs::exists(otherPath(exr, "global")) && fs::exists(otherPath(exr, "reached"))))) {
        fmt::print("reference {}: cached ({})\n", m.name, exr.string());
        if (!m.pathTrace)
          for (const char* model : {"global", "reached"})
            otherReferences_[model][m.name] = io::readImage(otherPath(exr, model).string());
        return io::readImage(exr.string());
      }
    }
    fmt::print("reference {}: rendering {} spp at {}x{}...\n", m.name, spp, width_, height_);
    std::fflush(stdout);
    Rendered r = render(m, spp, o_.seed + 7919);
    io::Image combined = combinedOnly(r.image);
    io::writeExr(exr.string(), combined);
    if (!m.pathTrace) {
      // The same samples composed with the paper's whole-scene I_a and with the reached one
      // (compose only, no ray).
      for (auto [model, name] : {std::pair{render::AmbientModel::Global, "global"}, std::pair{render::AmbientModel::Reached, "reached"}}) {
        obscurance_->setAmbientModel(model);
        obscurance_->compose();
        otherReferences_[name][m.name] = combinedOnly(obscurance_->image());
        io::writeExr(otherPath(exr, name).string(), otherReferences_[name][m.name]);
      }
      obscurance_->setAmbientModel(render::AmbientModel::Seen);
    }
    std::ofstream(txt) << description << "\nmade by: " << o_.commandLine << "\ngpu_ms: " << r.gpuMs << "\n";
    return combined;
  }

  static io::Image combinedOnly(const io::Image& image) {
    io::Image out;
    out.width = image.width;
    out.height = image.height;
    out.channels = {"combined.R", "combined.G", "combined.B"};
    int c = image.channelIndex("combined.R");
    out.pixels.reserve(std::size_t(image.width) * image.height * 3);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int k = 0; k < 3; ++k) out.pixels.push_back(image.at(x, y, c + k));
    return out;
  }

  // Obscurance method `name`'s reference composed with the `model` I_a ("global": the paper's,
  // "reached") instead of the Seen one (after reference() of it).
  const io::Image& otherReference(const std::string& model, const std::string& name) const {
    return otherReferences_.at(model).at(name);
  }
  static fs::path otherPath(fs::path exr, const std::string& model) {
    return exr.replace_extension(fmt::format(".{}-ia.exr", model));
  }

  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }
  const std::string& stem() const { return stem_; }

private:
  const ConvergeOptions& o_;
  const LoadedScene& loaded_;
  const gpu::Context& context_;
  std::unique_ptr<render::ObscuranceRenderer> obscurance_;
  std::unique_ptr<render::Denoiser> denoiser_; // bound to obscurance_'s frame
  std::unique_ptr<render::PathTracer> pathTracer_;
  scene::Camera camera_;
  std::uint32_t width_ = 0, height_ = 0;
  std::string stem_;
  mutable render::RenderStats statsCopy_;
  std::map<std::string, std::map<std::string, io::Image>> otherReferences_; // model -> method -> image
  io::Image farmReference_; // --pt-reference
};

void runConverge(const ConvergeOptions& o) {
  checkBackground(o.background);
  LoadedScene loaded = loadScene(o.scenePath, "node", std::nullopt); // first: a bad scene leaves no folder behind
  if (!o.background.empty()) loaded.scene.background = glm::vec3(o.background[0], o.background[1], o.background[2]);
  std::error_code ec;
  fs::create_directories(o.outputDir, ec);
  if (ec || !fs::is_directory(o.outputDir))
    throw InputError(fmt::format("{}: cannot create the output folder{}", o.outputDir, ec ? ": " + ec.message() : ""));
  gpu::Context context(o.device.contextOptions());
  buildTreeFor(loaded, context);
  fmt::print("{}\ndevice: {} ({})\n", sceneSummary(loaded), context.info().name, context.info().driver);
  warnIfUnlit(loaded);
  Study study(o, loaded, context);

  const std::vector<Method> methods = studyMethods(o);
  const Method& best = methods.front();
  const Method& pathMethod = methods.back();
  const io::Image obscuranceReference = study.reference(best);
  const io::Image ptReference = study.reference(pathMethod);
  // Secondary reflectors converge to an image of their own: their noise is measured against it.
  std::map<std::string, io::Image> reflectorReferences;
  for (const Method& m : methods)
    if (m.secondaryReflectors > 0.0f) reflectorReferences[m.name] = study.reference(m);
  auto noiseReference = [&](const Method& m) -> const io::Image& {
    if (m.pathTrace) return ptReference;
    return m.secondaryReflectors > 0.0f ? reflectorReferences.at(m.name) : obscuranceReference;
  };

  std::vector<analysis::Curve> curves;
  std::map<std::string, io::Image> atBudget; // each method's image at its budget
  const fs::path csvPath = fs::path(o.outputDir) / (study.stem() + ".convergence.csv");
  std::ofstream csv(csvPath);
  csv << "method,spp,rays_per_pixel,gpu_ms,rmse_noise,relmse_noise,mae_noise,rmse_trimmed_noise,"
         "rmse_vs_pathtrace,relmse_vs_pathtrace,mae_vs_pathtrace,rmse_trimmed_vs_pathtrace\n";
  for (const auto& m : methods) {
    analysis::Curve curve{.method = m.name, .points = {}};
    std::uint32_t maxSpp = m.pathTrace ? o.pathMaxSpp : o.obscuranceMaxSpp;
    for (std::uint32_t spp = 1; spp <= maxSpp; spp *= 2) {
      Rendered r = study.render(m, spp, o.seed + spp);
      analysis::CurvePoint p{.spp = spp, .raysPerPixel = r.rays, .gpuMs = r.gpuMs,
                           .noise = analysis::imageError(r.image, noiseReference(m)),
                           .total = analysis::imageError(r.image, ptReference)};
      if (spp == m.budgetSpp) atBudget[m.name] = r.image;
      curve.points.push_back(p);
      csv << fmt::format("{},{},{:.2f},{:.3f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", m.name, spp,
                         p.raysPerPixel, p.gpuMs, p.noise.rmse, p.noise.relMse, p.noise.mae, p.noise.rmseTrimmed,
                         p.total.rmse, p.total.relMse, p.total.mae, p.total.rmseTrimmed);
      fmt::print("{:20s} spp {:4d}  {:7.1f} rays/px  {:9.1f} ms  noise RMSE {:.5f} (trimmed {:.5f}, MAE {:.5f})  "
                 "vs PT RMSE {:.5f}\n",
                 m.name, spp, p.raysPerPixel, p.gpuMs, p.noise.rmse, p.noise.rmseTrimmed, p.noise.mae, p.total.rmse);
      std::fflush(stdout);
    }
    curves.push_back(curve);
  }
  csv.close();

  const analysis::Curve& pt = curves.back();
  nlohmann::json summary = {{"scene", o.scenePath}, {"width", study.width()}, {"height", study.height()},
                            {"device", context.info().name}, {"command", o.commandLine}};
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
    const Method& m = methods[i];
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
      const analysis::TimeAt equalNoise = analysis::timeToReach(pt, noise, analysis::ErrorKind::Noise, metric);
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
    summary["methods"][m.name] = entry;
  }

  // What a user sees: the obscurance image at the paper's budget and path tracing at equal GPU time.
  if (atBudget.contains(best.name)) {
    const analysis::CurvePoint* point = nullptr;
    for (const auto& p : curves.front().points)
      if (p.spp == best.budgetSpp) point = &p;
    const double msPerPath = pt.points.back().gpuMs / pt.points.back().spp;
    const auto ptSpp = static_cast<std::uint32_t>(std::max(1.0, std::round(point->gpuMs / msPerPath)));
    Rendered equalTime = study.render(pathMethod, ptSpp, o.seed + 104729);
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
  std::string plot = fmt::format("/usr/bin/python3 {}/tools/plot_convergence.py '{}' '{}' '{}'", OBSCURA_SOURCE_DIR,
                                 csvPath.string(), plotPath.string(), study.stem());
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
  cmd->add_option("--max-spp", o->obscuranceMaxSpp, "largest obscurance sample count (powers of 2 up to it)")
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
  cmd->add_option("--background", o->background, "R,G,B: a constant sky for both methods (as render --background)")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--emission-samples", o->emissionSamples,
                  fmt::format("obscurance methods: camera rays per sample for the emission the camera sees (render "
                              "--emission-samples; default {})", kObscuranceEmissionSamples))
      ->check(CLI::Range(1u, gpu::kMaxEmissionSamples));
  cmd->add_option("--pt-emission-samples", o->pathEmissionSamples,
                  fmt::format("path tracing: the same (default {})", kPathEmissionSamples))
      ->check(CLI::Range(1u, gpu::kMaxEmissionSamples));
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
