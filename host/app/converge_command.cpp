// obscura converge SCENE -o DIR — speed against error [SPEC §4]. Renders converged references
// (cached as EXR in DIR, each with a .txt naming the command and settings that made it), then
// each method at increasing sample counts, recording GPU time and the error against (a) the same
// method converged (noise) and (b) converged path tracing (bias + noise). Writes a CSV, a log-log
// plot (tools/plot_convergence.py) and prints the equal-noise speed-up of obscurances over path
// tracing at the paper's budget, the obscurance bias floor, and when path tracing beats it.
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "analysis/convergence.h"
#include "analysis/image_error.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

struct ConvergeOptions {
  std::string scenePath;
  std::string outputDir;
  std::uint32_t width = 128;
  std::uint32_t obscuranceMaxSpp = 16;
  std::uint32_t pathMaxSpp = 256;
  std::uint32_t referenceFactor = 64;   // a reference has this many times the largest curve's spp
  std::uint32_t pathReferenceSpp = 0;   // 0: referenceFactor x pathMaxSpp
  std::uint32_t seed = 1;
  std::string commandLine;
  DeviceOptions device;
};

struct Method {
  std::string name;
  bool pathTrace = false;
  render::RhoKind rho = render::RhoKind::Sqrt;
  bool systematic = true;
};

const std::vector<Method> kMethods = {
    {"obscurance-systematic-sqrt", false, render::RhoKind::Sqrt, true},
    {"obscurance-random-sqrt", false, render::RhoKind::Sqrt, false},
    {"obscurance-systematic-ao", false, render::RhoKind::Ao, true},
    {"obscurance-random-ao", false, render::RhoKind::Ao, false},
    {"pathtrace", true, render::RhoKind::Sqrt, true},
};

// The paper's budget [RTO §4.1]: 8 primary samples x (5 obscurance + 5 shadow rays) per hit.
constexpr std::uint32_t kPaperSpp = 8, kPaperRays = 5;

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
  }

  // Renders with the study's persistent renderers: the scene is uploaded and the pipelines are
  // made once per method family, not once per render.
  Rendered render(const Method& m, std::uint32_t spp, std::uint32_t seed) {
    Rendered r;
    const render::RenderStats* stats = nullptr;
    if (m.pathTrace) {
      render::PathTraceSettings s{.width = width_, .height = height_, .spp = spp, .seed = seed, .camera = camera_};
      if (!pathTracer_) pathTracer_ = std::make_unique<render::PathTracer>(context_, loaded_.scene, loaded_.bvh, s);
      pathTracer_->configure(s);
      pathTracer_->render();
      r.image = pathTracer_->image();
      statsCopy_ = pathTracer_->stats();
    } else {
      render::ObscuranceSettings s;
      s.width = width_;
      s.height = height_;
      s.spp = spp;
      s.seed = seed;
      s.camera = camera_;
      s.shadowRays = kPaperRays;
      s.obscuranceRays = kPaperRays;
      s.rho = m.rho;
      s.systematic = m.systematic;
      if (!obscurance_)
        obscurance_ = std::make_unique<render::ObscuranceRenderer>(context_, loaded_.scene, loaded_.bvh, s);
      obscurance_->configure(s);
      obscurance_->render();
      r.image = obscurance_->image();
      statsCopy_ = obscurance_->stats();
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

  // The converged image of a method, from the cache when the same settings made it.
  io::Image reference(const Method& m) {
    std::uint32_t spp = m.pathTrace ? (o_.pathReferenceSpp ? o_.pathReferenceSpp : o_.referenceFactor * o_.pathMaxSpp)
                                    : o_.referenceFactor * o_.obscuranceMaxSpp;
    fs::path exr = fs::path(o_.outputDir) / fmt::format("{}.{}.reference.exr", stem_, m.name);
    fs::path txt = exr;
    txt.replace_extension(".txt");
    std::string description = fmt::format("scene={} method={} width={} height={} spp={} seed={} shadow_rays={} obs_rays={}",
                                          o_.scenePath, m.name, width_, height_, spp, o_.seed + 7919, kPaperRays, kPaperRays);
    if (fs::exists(exr) && fs::exists(txt)) {
      std::ifstream in(txt);
      std::string first;
      std::getline(in, first);
      if (first == description) {
        fmt::print("reference {}: cached ({})\n", m.name, exr.string());
        return io::readImage(exr.string());
      }
    }
    fmt::print("reference {}: rendering {} spp at {}x{}...\n", m.name, spp, width_, height_);
    std::fflush(stdout);
    Rendered r = render(m, spp, o_.seed + 7919);
    io::Image combined = combinedOnly(r.image);
    io::writeExr(exr.string(), combined);
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

  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }
  const std::string& stem() const { return stem_; }

private:
  const ConvergeOptions& o_;
  const LoadedScene& loaded_;
  const gpu::Context& context_;
  std::unique_ptr<render::ObscuranceRenderer> obscurance_;
  std::unique_ptr<render::PathTracer> pathTracer_;
  scene::Camera camera_;
  std::uint32_t width_ = 0, height_ = 0;
  std::string stem_;
  mutable render::RenderStats statsCopy_;
};

void runConverge(const ConvergeOptions& o) {
  LoadedScene loaded = loadScene(o.scenePath); // first: a bad scene leaves no folder behind
  std::error_code ec;
  fs::create_directories(o.outputDir, ec);
  if (ec || !fs::is_directory(o.outputDir))
    throw InputError(fmt::format("{}: cannot create the output folder{}", o.outputDir, ec ? ": " + ec.message() : ""));
  gpu::Context context(o.device.contextOptions());
  fmt::print("{}\ndevice: {} ({})\n", sceneSummary(loaded), context.info().name, context.info().driver);
  Study study(o, loaded, context);

  std::map<std::string, io::Image> references;
  for (const auto& m : kMethods) references[m.name] = study.reference(m);
  const io::Image& ptReference = references.at("pathtrace");

  std::vector<render::Curve> curves;
  const fs::path csvPath = fs::path(o.outputDir) / (study.stem() + ".convergence.csv");
  std::ofstream csv(csvPath);
  csv << "method,spp,rays_per_pixel,gpu_ms,rmse_noise,relmse_noise,rmse_vs_pathtrace,relmse_vs_pathtrace\n";
  for (const auto& m : kMethods) {
    render::Curve curve{.method = m.name, .points = {}};
    std::uint32_t maxSpp = m.pathTrace ? o.pathMaxSpp : o.obscuranceMaxSpp;
    for (std::uint32_t spp = 1; spp <= maxSpp; spp *= 2) {
      Rendered r = study.render(m, spp, o.seed + spp);
      render::ImageError noise = render::imageError(r.image, references.at(m.name));
      render::ImageError total = render::imageError(r.image, ptReference);
      render::CurvePoint p{.spp = spp, .raysPerPixel = r.rays, .gpuMs = r.gpuMs, .rmseNoise = noise.rmse,
                           .relMseNoise = noise.relMse, .rmseReference = total.rmse, .relMseReference = total.relMse};
      curve.points.push_back(p);
      csv << fmt::format("{},{},{:.2f},{:.3f},{:.6g},{:.6g},{:.6g},{:.6g}\n", m.name, spp, p.raysPerPixel, p.gpuMs,
                         p.rmseNoise, p.relMseNoise, p.rmseReference, p.relMseReference);
      fmt::print("{:28s} spp {:4d}  {:8.1f} rays/px  {:9.1f} ms  noise RMSE {:.5f}  vs PT RMSE {:.5f}\n", m.name, spp,
                 p.raysPerPixel, p.gpuMs, p.rmseNoise, p.rmseReference);
      std::fflush(stdout);
    }
    curves.push_back(curve);
  }
  csv.close();

  // Summary at the paper's budget: 8 spp x (5 + 5) rays = 40 + 40 rays per pixel [RTO §4.1].
  const render::Curve& obs = curves.front();
  const render::Curve& pt = curves.back();
  const render::CurvePoint* budget = nullptr;
  for (const auto& p : obs.points)
    if (p.spp == kPaperSpp) budget = &p;
  nlohmann::json summary = {{"scene", o.scenePath}, {"width", study.width()}, {"height", study.height()},
                            {"device", context.info().name}};
  if (budget) {
    render::TimeAt ptTime = render::timeToReach(pt, budget->rmseNoise, render::ErrorKind::Noise);
    double speedUp = ptTime.valid ? ptTime.ms / budget->gpuMs : 0.0;
    fmt::print("\nequal-noise speed-up at the paper's budget (8 spp, 5+5 rays per hit): obscurance noise RMSE {:.5f} "
               "in {:.1f} ms; path tracing reaches it in {:.1f} ms{} -> {:.1f}x\n",
               budget->rmseNoise, budget->gpuMs, ptTime.ms, ptTime.extrapolated ? " (extrapolated, RMSE ~ t^-1/2)" : "",
               speedUp);
    summary["obscurance_noise_rmse_at_budget"] = budget->rmseNoise;
    summary["obscurance_ms_at_budget"] = budget->gpuMs;
    summary["pathtrace_ms_to_equal_noise"] = ptTime.ms;
    summary["pathtrace_equal_noise_extrapolated"] = ptTime.extrapolated;
    summary["equal_noise_speedup"] = speedUp;
  }
  render::ImageError bias = render::imageError(references.at(obs.method), ptReference);
  render::TimeAt ptBelow = render::timeToReach(pt, bias.rmse, render::ErrorKind::AgainstReference);
  fmt::print("obscurance bias floor (converged obscurance vs converged path tracing): RMSE {:.5f}, relMSE {:.5f}\n",
             bias.rmse, bias.relMse);
  fmt::print("path tracing's error falls below that floor after {:.1f} ms{}\n", ptBelow.ms,
             ptBelow.extrapolated ? " (extrapolated)" : "");
  summary["bias_floor_rmse"] = bias.rmse;
  summary["bias_floor_relmse"] = bias.relMse;
  summary["pathtrace_ms_below_bias_floor"] = ptBelow.ms;
  summary["pathtrace_below_bias_floor_extrapolated"] = ptBelow.extrapolated;
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
  cmd->add_option("--seed", o->seed, "seed");
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
