#include "analysis/convergence_study.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "farm/merge.h"
#include "render/method.h"

namespace obscura::analysis {

namespace {

// The cached reference's .txt line with its own noise (RMSE, trimmed RMSE, MAE).
constexpr const char* kOwnNoiseKey = "own_noise(rmse,rmse_trimmed,mae):";

std::string emissionName(std::uint32_t samples, bool atEdges) {
  return atEdges ? fmt::format("{}_at_edges", samples) : std::to_string(samples);
}

// Each method with its best estimators, the paper's estimator for reproduction, and a real-time
// budget (one primary sample with 1 + 1 rays per hit). Path tracing comes last.
const render::ObscuranceSettings kDefaults;

const std::vector<StudyMethod> kMethods = {
    // What `obscura render` does: its light sampling, its split of the paper's ten rays per hit, and
    // past the paper's 8 spp the paths that correct the frame (--pt-correction auto).
    {"obscurance", false, render::LightSampling::Spatial, kDefaults.shadowRays, kPaperSpp,
     "the defaults: spatial light sampling, 8 shadow + 2 obscurance rays per hit, 8 spp; past 8 spp corrected by "
     "spp - 8 paths (at least 4)",
     0.0f, false, kDefaults.obscuranceRays, 0, true, true},
    // The same without the paths (--pt-correction 0): the obscurances alone, down to their bias.
    {"obscurance-uncorrected", false, render::LightSampling::Spatial, kDefaults.shadowRays, kPaperSpp,
     "as obscurance, never corrected by paths (--pt-correction 0)", 0.0f, false, kDefaults.obscuranceRays},
    // The paper's budget as the paper splits it, and with the paper's light sampling too.
    {"obscurance-5+5", false, render::LightSampling::Spatial, render::kPaperShadowRays, kPaperSpp,
     "spatial light sampling, 5 + 5 rays per hit, 8 spp (the paper's budget)", 0.0f, false,
     render::kPaperObscuranceRays},
    {"obscurance-paper", false, render::LightSampling::Area, render::kPaperShadowRays, kPaperSpp,
     "the paper's light sampling (by power, by area), 5 + 5 rays per hit, 8 spp", 0.0f, false,
     render::kPaperObscuranceRays},
    // What scaling a specular path vertex's rays by its throughput (the default) saves and costs.
    {"obscurance-per-hit-vertices", false, render::LightSampling::Spatial, kDefaults.shadowRays, kPaperSpp,
     "as obscurance, its rays at every specular path vertex too (render --vertex-rays per-hit)", 0.0f, false,
     kDefaults.obscuranceRays, 0, false},
    {"obscurance-realtime", false, render::LightSampling::Spatial, 1, 1, "spatial, 1+1 rays per hit, 1 spp"},
    // The window's frames: the same, denoised (one frame alone, no history), error measured.
    {"obscurance-denoised", false, render::LightSampling::Spatial, kDefaults.shadowRays, 1,
     "as obscurance, 1 spp, denoised (a-trous on demodulated terms)", 0.0f, true, kDefaults.obscuranceRays},
    {"obscurance-realtime-denoised", false, render::LightSampling::Spatial, 1, 1,
     "spatial, 1+1 rays per hit, denoised, 1 spp", 0.0f, true},
    {"pathtrace", true, render::LightSampling::Spatial, 0, 1, "path tracing, NEE with spatial light sampling + MIS"},
};

} // namespace

std::uint32_t StudyMethod::correctionPaths(std::uint32_t spp) const {
  return defaultCorrection ? render::PathCorrection::defaultPaths(spp) : 0u;
}

// The methods a study runs: kMethods, and with --secondary-reflectors the best obscurance method
// with them too (before path tracing, which stays last).
std::vector<StudyMethod> studyMethods(const StudySettings& o) {
  std::vector<StudyMethod> methods = kMethods;
  if (o.secondaryReflectors > 0.0f) {
    StudyMethod m = methods.front();
    m.defaultCorrection = false; // its bias floor is what it is for
    m.name = "obscurance-reflectors";
    m.what = fmt::format("as obscurance, with secondary reflectors marked at {:g} x mean direct irradiance",
                         o.secondaryReflectors);
    m.secondaryReflectors = o.secondaryReflectors;
    methods.insert(methods.end() - 1, m);
  }
  if (o.emissionSamples > 1) { // what the emission rays change, in the same run (default: at the edges)
    StudyMethod m = methods.front();
    m.defaultCorrection = false;
    m.name = "obscurance-primary-emission";
    m.what = "as obscurance, the seen emission from the primary rays alone (--emission-samples 1)";
    m.emissionSamples = 1;
    methods.insert(methods.begin() + 1, m);
  }
  return methods;
}

ConvergenceStudy::ConvergenceStudy(const StudySettings& o, const scene::Scene& studied, const bvh::Bvh& bvh,
                                   const gpu::Context& context)
    : o_(o), scene_(studied), bvh_(bvh), context_(context) {
  camera_ = studied.cameras.empty() ? scene::defaultCamera(studied.bounds) : studied.cameras.front();
  float aspect = camera_.aspectRatio > 0.0f ? camera_.aspectRatio : 1.0f;
  width_ = o.width;
  height_ = std::max(1u, static_cast<std::uint32_t>(std::lround(static_cast<float>(o.width) / aspect)));
  stem_ = std::filesystem::path(o.scenePath).stem().string();
  // Checked before anything is rendered: a wrong reference fails the study at once.
  if (!o.pathReferenceFile.empty()) farmReference_ = farmReference();
}

render::PathTraceSettings ConvergenceStudy::pathSettings(const StudyMethod& m, std::uint32_t spp,
                                                        std::uint32_t seed) const {
  return {.width = width_, .height = height_, .spp = spp, .seed = seed, .camera = camera_,
          .lightSampling = m.lightSampling, .emissionSamples = o_.pathEmissionSamples,
          .emissionAtEdges = o_.pathEmissionAtEdges};
}

StudyRender ConvergenceStudy::render(const StudyMethod& m, std::uint32_t spp, std::uint32_t seed) {
  if (warmedUp_.insert(m.name).second) render(m, 1, seed);
  StudyRender r;
  const render::RenderStats* stats = nullptr;
  if (m.pathTrace) {
    const render::PathTraceSettings s = pathSettings(m, spp, seed);
    if (!pathTracer_) pathTracer_ = std::make_unique<render::PathTracer>(context_, scene_, bvh_, s);
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
    s.emissionAtEdges = m.emissionSamples ? false : o_.emissionAtEdges;
    s.seed = seed;
    s.camera = camera_;
    s.shadowRays = m.raysPerHit;
    s.obscuranceRays = m.obscuranceRays ? m.obscuranceRays : m.raysPerHit;
    s.lightSampling = m.lightSampling;
    s.ambient = render::AmbientModel::Seen; // the least biased I_a; Reached and Global composed beside it
    s.dMax = o_.dMax;
    s.escapes = o_.escapes;
    s.secondaryReflectors = m.secondaryReflectors;
    s.vertexRaysByThroughput = m.vertexRaysByThroughput;
    if (!obscurance_)
      obscurance_ = std::make_unique<render::ObscuranceRenderer>(context_, scene_, bvh_, s);
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
    if (const std::uint32_t paths = m.correctionPaths(spp); paths > 0) {
      // The paths with a seed stream of their own; their time and rays count with the frame's.
      const render::PathTraceSettings ps = pathSettings(m, paths, seed + 0x9e3779b9u);
      if (!pathTracer_) pathTracer_ = std::make_unique<render::PathTracer>(context_, scene_, bvh_, ps);
      pathTracer_->configure(ps);
      pathTracer_->render();
      if (!correction_) correction_ = std::make_unique<render::PathCorrection>(context_, *obscurance_, *pathTracer_);
      correction_->correct(*obscurance_, *pathTracer_);
      r.image = correction_->image();
      r.gpuMs += correction_->lastGpuMs();
      const render::RenderStats pathStats = pathTracer_->stats();
      for (const auto& [name, pass] : pathStats.passes) statsCopy_.passes["correction." + name] = pass;
      statsCopy_.truncatedTraversals += pathStats.truncatedTraversals;
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

io::Image ConvergenceStudy::farmReference() const {
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

io::Image ConvergenceStudy::reference(const StudyMethod& m) {
  if (m.pathTrace && !o_.pathReferenceFile.empty()) return farmReference_;
  std::uint32_t spp = m.pathTrace ? (o_.pathReferenceSpp ? o_.pathReferenceSpp : o_.referenceFactor * o_.pathMaxSpp)
                                  : o_.referenceFactor * o_.obscuranceMaxSpp;
  std::filesystem::path exr = std::filesystem::path(o_.outputDir) / fmt::format("{}.{}.reference.exr", stem_, m.name);
  std::filesystem::path txt = exr;
  txt.replace_extension(".txt");
  std::string description = fmt::format("scene={} method={} width={} height={} spp={} (two halves) seed={} "
                                        "rays_per_hit={}+{} emission_samples={} light_sampling={}{}{}",
                                        o_.scenePath, m.name, width_, height_, spp, o_.seed + 7919, m.raysPerHit,
                                        m.obscuranceRays ? m.obscuranceRays : m.raysPerHit,
                                        m.pathTrace ? emissionName(o_.pathEmissionSamples, o_.pathEmissionAtEdges)
                                                    : emissionName(o_.emissionSamples, o_.emissionAtEdges),
                                        nameOf(render::kLightSamplingNames, m.lightSampling),
                                        m.pathTrace ? "" : fmt::format(" ambient=seen+reached+global dmax={} escapes={} secondary_reflectors={}",
                                                                       o_.dMax, nameOf(render::kEscapeModelNames, o_.escapes),
                                                                       m.secondaryReflectors),
                                        o_.background.empty() ? "" : fmt::format(" background={}", fmt::join(o_.background, ",")));
  if (std::filesystem::exists(exr) && std::filesystem::exists(txt)) {
    std::ifstream in(txt);
    std::string first;
    std::getline(in, first);
    if (first == description &&
        (m.pathTrace || (std::filesystem::exists(otherPath(exr, "global")) && std::filesystem::exists(otherPath(exr, "reached"))))) {
      fmt::print("reference {}: cached ({})\n", m.name, exr.string());
      for (std::string line; std::getline(in, line);) {
        std::istringstream words(line);
        std::string key;
        ImageError noise;
        if (words >> key >> noise.rmse >> noise.rmseTrimmed >> noise.mae && key == kOwnNoiseKey)
          referenceNoise_[m.name] = noise;
      }
      if (!m.pathTrace)
        for (const char* model : {"global", "reached"})
          otherReferences_[model][m.name] = io::readImage(otherPath(exr, model).string());
      return io::readImage(exr.string());
    }
  }
  fmt::print("reference {}: rendering 2 x {} spp at {}x{}...\n", m.name, spp / 2, width_, height_);
  std::fflush(stdout);
  // Two halves with seeds of their own: the reference is their mean, and their difference says how
  // converged it is (referenceNoise). Each obscurance half is also composed with the paper's
  // whole-scene I_a and with the reached one (compose only, no ray).
  struct Half {
    io::Image seen;
    std::map<std::string, io::Image> other; // model -> image
    double gpuMs = 0.0;
  };
  // An obscurance method's reference is the obscurances' own converged image: no paths correct it.
  StudyMethod uncorrected = m;
  uncorrected.defaultCorrection = false;
  auto renderHalf = [&](std::uint32_t seed) {
    Half h;
    StudyRender r = render(uncorrected, std::max(1u, spp / 2), seed);
    h.seen = combinedOnly(r.image);
    h.gpuMs = r.gpuMs;
    if (!m.pathTrace) {
      for (auto [model, name] : {std::pair{render::AmbientModel::Global, "global"}, std::pair{render::AmbientModel::Reached, "reached"}}) {
        obscurance_->setAmbientModel(model);
        obscurance_->compose();
        h.other[name] = combinedOnly(obscurance_->image());
      }
      obscurance_->setAmbientModel(render::AmbientModel::Seen);
    }
    return h;
  };
  const Half a = renderHalf(o_.seed + 7919), b = renderHalf(o_.seed + 7919 + 104729);
  const io::Image combined = meanOf(a.seen, b.seen);
  referenceNoise_[m.name] = ownNoise(a.seen, b.seen);
  io::writeExr(exr.string(), combined);
  for (const auto& [name, image] : a.other) {
    otherReferences_[name][m.name] = meanOf(image, b.other.at(name));
    io::writeExr(otherPath(exr, name).string(), otherReferences_[name][m.name]);
  }
  const ImageError& noise = referenceNoise_.at(m.name);
  std::ofstream(txt) << description << "\nmade by: " << o_.commandLine << "\ngpu_ms: " << a.gpuMs + b.gpuMs
                     << "\n" << fmt::format("{} {} {} {}", kOwnNoiseKey, noise.rmse, noise.rmseTrimmed, noise.mae) << "\n";
  return combined;
}

// Half of each measure of A - B: the error of (A + B) / 2 when A and B are independent estimates
// with the same spread (A - B has twice the variance of either, their mean half of it, so the
// mean's RMSE is RMSE(A - B) / 2; for normal errors the mean absolute error scales the same).
ImageError ConvergenceStudy::ownNoise(const io::Image& a, const io::Image& b) {
  const ImageError d = imageError(a, b);
  return {.rmse = d.rmse / 2.0, .relMse = d.relMse / 4.0, .mae = d.mae / 2.0, .rmseTrimmed = d.rmseTrimmed / 2.0,
          .meanRatio = 1.0};
}

io::Image ConvergenceStudy::meanOf(const io::Image& a, const io::Image& b) {
  io::Image out = a;
  for (std::size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = 0.5f * (a.pixels[i] + b.pixels[i]);
  return out;
}

const ImageError* ConvergenceStudy::referenceNoise(const std::string& method) const {
  const auto it = referenceNoise_.find(method);
  return it == referenceNoise_.end() ? nullptr : &it->second;
}

io::Image ConvergenceStudy::combinedOnly(const io::Image& image) {
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

const io::Image& ConvergenceStudy::otherReference(const std::string& model, const std::string& name) const {
  return otherReferences_.at(model).at(name);
}

std::filesystem::path ConvergenceStudy::otherPath(std::filesystem::path exr, const std::string& model) {
  return exr.replace_extension(fmt::format(".{}-ia.exr", model));
}

} // namespace obscura::analysis
