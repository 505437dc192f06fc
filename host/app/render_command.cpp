// obscura render SCENE -o out.{exr,png} [--width --height --spp --aov NAME... --metrics m.json]
#include <algorithm>
#include <cmath>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "gpu/buffer.h"
#include "io/image_io.h"
#include "render/aov_render.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"

namespace obscura::app {
namespace {

struct RenderOptions {
  std::string scenePath;
  std::string output;
  std::uint32_t width = 0, height = 0; // 0 = from the camera's aspect, 512 on the long side
  std::uint32_t spp = 4;
  std::uint32_t seed = 1;
  int camera = -1;
  std::vector<std::string> aovs;
  std::string metrics;
  float exposure = 0.0f;
  std::string method = "obscurance";
  render::ObscuranceSettings obscurance;
  std::string rho = "sqrt";
  std::string sampling = "systematic";
  bool noBleed = false;
  float dMax = 0.0f;
  bool dMaxGiven = false;
  DeviceOptions device;
};

scene::Camera chooseCamera(const scene::Scene& scene, int index) {
  if (index >= 0) {
    if (index >= static_cast<int>(scene.cameras.size()))
      throw InputError(fmt::format("--camera {}: the scene {} has {} cameras", index, scene.sourcePath,
                                   scene.cameras.size()));
    return scene.cameras[index];
  }
  return scene.cameras.empty() ? scene::defaultCamera(scene.bounds) : scene.cameras.front();
}

void chooseSize(RenderOptions& o, const scene::Camera& camera) {
  float aspect = camera.aspectRatio > 0.0f ? camera.aspectRatio : 1.0f;
  if (o.width == 0 && o.height == 0) {
    o.width = aspect >= 1.0f ? 512u : static_cast<std::uint32_t>(std::lround(512.0f * aspect));
    o.height = aspect >= 1.0f ? static_cast<std::uint32_t>(std::lround(512.0f / aspect)) : 512u;
  } else if (o.height == 0) {
    o.height = std::max(1u, static_cast<std::uint32_t>(std::lround(static_cast<float>(o.width) / aspect)));
  } else if (o.width == 0) {
    o.width = std::max(1u, static_cast<std::uint32_t>(std::lround(static_cast<float>(o.height) * aspect)));
  }
}

// Keeps only the requested AOVs' channels (all when none requested).
io::Image selectAovs(const io::Image& all, const std::vector<std::string>& aovs) {
  if (aovs.empty()) return all;
  io::Image out;
  out.width = all.width;
  out.height = all.height;
  std::vector<int> source;
  for (const auto& aov : aovs)
    for (const auto& channel : render::aovChannels(aov)) {
      out.channels.push_back(channel);
      source.push_back(all.channelIndex(channel));
    }
  out.pixels.resize(std::size_t(out.width) * out.height * out.channels.size());
  std::size_t k = 0;
  for (int y = 0; y < all.height; ++y)
    for (int x = 0; x < all.width; ++x)
      for (int c : source) out.pixels[k++] = all.at(x, y, c);
  return out;
}

void printProgress(std::uint32_t done, std::uint32_t total, double seconds, std::uint64_t raysPerSample) {
  double rate = seconds > 0 ? static_cast<double>(raysPerSample) * done / seconds / 1e6 : 0.0;
  double eta = done > 0 ? seconds / done * (total - done) : 0.0;
  std::fprintf(stderr, "\rrender: %3.0f%%  %6.2f Mrays/s  ETA %5.1f s ", 100.0 * done / total, rate, eta);
  if (done == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

// Fails now, before any work, when `path` cannot be written (its folder is missing, is a file,
// or refuses a new file): a late failure would leave a finished image and no metrics.
void checkWritable(const std::string& path) {
  std::string probe = path + ".probe.tmp";
  {
    std::ofstream out(probe);
    if (!out) throw InputError(fmt::format("{}: cannot write metrics here", path));
  }
  std::remove(probe.c_str());
}

void writeMetrics(const std::string& path, const nlohmann::json& json) {
  std::string temp = path + ".tmp";
  {
    std::ofstream out(temp);
    if (!out) throw InputError(fmt::format("{}: cannot write metrics", path));
    out << json.dump(2) << "\n";
    if (!out) throw InputError(fmt::format("{}: cannot write metrics", path));
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    throw InputError(fmt::format("{}: cannot write metrics", path));
  }
}

// Writes the image (EXR layers or PNG of one AOV) and the metrics; fails on truncated traversals.
void writeOutputs(const RenderOptions& o, const io::Image& image, const render::RenderStats& stats,
                  const gpu::Context& context, const LoadedScene& loaded, const nlohmann::json& method) {
  for (const auto& note : stats.notes) fmt::print(stderr, "note: {}\n", note);
  if (stats.truncatedTraversals > 0)
    throw DeviceError(fmt::format("{} traversals ran out of steps (kMaxTraversalSteps); the image would be wrong",
                                  stats.truncatedTraversals));

  io::Image selected = selectAovs(image, o.aovs);
  if (io::extensionOf(o.output) == "exr") {
    io::writeExr(o.output, selected);
  } else {
    std::string first = o.aovs.empty() ? "combined" : o.aovs.front();
    const auto channels = render::aovChannels(first);
    io::writePng(o.output, image, image.channelIndex(channels.front()), o.exposure,
                 static_cast<int>(channels.size()));
  }

  nlohmann::json passes = nlohmann::json::object();
  double totalMs = 0.0;
  std::uint64_t totalRays = 0;
  for (const auto& [name, pass] : stats.passes) {
    passes[name] = {{"gpu_ms", pass.gpuMs}, {"rays", pass.rays},
                    {"mrays_per_s", pass.gpuMs > 0 ? static_cast<double>(pass.rays) / (pass.gpuMs * 1e3) : 0.0}};
    totalMs += pass.gpuMs;
    totalRays += pass.rays;
  }
  double mrays = totalMs > 0 ? static_cast<double>(totalRays) / (totalMs * 1e3) : 0.0;
  fmt::print(stderr, "render: {}x{}, {} spp, {} rays in {:.1f} ms GPU ({:.2f} Mrays/s), {:.2f} s wall -> {}\n",
             o.width, o.height, o.spp, totalRays, totalMs, mrays, stats.wallSeconds, o.output);
  if (!o.metrics.empty()) {
    nlohmann::json json = {
        {"device", {{"name", context.info().name}, {"driver", context.info().driver},
                    {"type", context.info().type}, {"api", context.info().apiVersion}}},
        {"scene", sceneJson(loaded)},
        {"image", {{"width", o.width}, {"height", o.height}, {"spp", o.spp}, {"seed", o.seed}, {"output", o.output}}},
        {"passes", passes},
        {"method", method},
        {"gpu_ms", totalMs},
        {"rays", totalRays},
        {"mrays_per_s", mrays},
        {"wall_s", stats.wallSeconds},
        {"device_bytes", stats.deviceBytes},
        {"truncated_traversals", stats.truncatedTraversals}};
    writeMetrics(o.metrics, json);
  }
}

void runRender(RenderOptions& o) {
  std::string ext = io::extensionOf(o.output);
  if (ext != "exr" && ext != "png")
    throw InputError(fmt::format("{}: the output must be .exr or .png", o.output));
  static const std::vector<std::string> pathAovs = {"combined"};
  const auto& known = o.method == "pathtrace" ? pathAovs : render::obscuranceAovNames();
  for (const auto& aov : o.aovs)
    if (std::find(known.begin(), known.end(), aov) == known.end())
      throw InputError(fmt::format("--aov {}: unknown AOV (known: {})", aov, fmt::join(known, ", ")));
  if (o.dMaxGiven && !(std::isfinite(o.dMax) && o.dMax > 0.0f))
    throw InputError(fmt::format("--dmax {}: must be a finite positive distance in scene units", o.dMax));
  if (!o.metrics.empty()) checkWritable(o.metrics);

  LoadedScene loaded = loadScene(o.scenePath);
  scene::Camera camera = chooseCamera(loaded.scene, o.camera);
  chooseSize(o, camera);
  fmt::print(stderr, "{}\n", sceneSummary(loaded));

  gpu::Context context(o.device.contextOptions());
  const std::size_t lightCount = loaded.scene.lightGroups.size() + loaded.scene.punctualLights.size();
  std::uint64_t need = render::obscuranceBytesNeeded(o.width, o.height, lightCount);
  std::uint64_t largest = render::obscuranceLargestBuffer(o.width, o.height, lightCount);
  if (need > context.info().deviceLocalBytes || largest > context.info().maxStorageBufferRange)
    throw InputError(fmt::format("{}x{}: the frame buffers would need {:.1f} MiB (the largest one {:.1f} MiB), more "
                                 "than the device '{}' offers ({:.0f} MiB, {:.0f} MiB per buffer)",
                                 o.width, o.height, static_cast<double>(need) / 1048576.0,
                                 static_cast<double>(largest) / 1048576.0, context.info().name,
                                 static_cast<double>(context.info().deviceLocalBytes) / 1048576.0,
                                 static_cast<double>(context.info().maxStorageBufferRange) / 1048576.0));
  fmt::print(stderr, "device: {} ({})\n", context.info().name, context.info().driver);

  render::ObscuranceSettings settings = o.obscurance;
  settings.width = o.width;
  settings.height = o.height;
  settings.spp = o.spp;
  settings.seed = o.seed;
  settings.camera = camera;
  settings.dMax = o.dMax;
  settings.rho = o.rho == "exp" ? render::RhoKind::Exp : o.rho == "ao" ? render::RhoKind::Ao : render::RhoKind::Sqrt;
  settings.systematic = o.sampling == "systematic";
  settings.colourBleeding = !o.noBleed;
  const bool tty = ::isatty(STDERR_FILENO);
  const std::uint64_t raysPerSample = std::uint64_t(o.width) * o.height *
                                      (1 + settings.shadowRays + settings.obscuranceRays);
  const render::ProgressFn progress =
      tty ? render::ProgressFn([&](auto d, auto t, auto s) { printProgress(d, t, s, raysPerSample); })
          : render::ProgressFn();
  if (o.method == "pathtrace") {
    render::PathTraceSettings pt{.width = o.width, .height = o.height, .spp = o.spp, .seed = o.seed,
                                 .camera = camera, .maxDepth = settings.maxDepth};
    render::PathTraceResult traced = render::renderPathTraced(context, loaded.scene, loaded.bvh, pt, progress);
    writeOutputs(o, traced.image, traced.stats, context, loaded, {{"method", "pathtrace"}, {"max_depth", pt.maxDepth}});
    return;
  }
  render::ObscuranceResult result = render::renderObscurances(context, loaded.scene, loaded.bvh, settings, progress);
  render::RenderStats& stats = result.stats;
  io::Image& image = result.image;
  const glm::vec3 ia = result.ambientIntensity, rAve = result.ambient.averageReflectance;
  fmt::print(stderr, "obscurance: dmax {:.4g}, rho {}, {} sampling, {}; R_ave ({:.4f}, {:.4f}, {:.4f}), "
                     "I_a ({:.4g}, {:.4g}, {:.4g}); {} lights\n",
             result.dMax, o.rho, o.sampling, o.noBleed ? "grey" : "colour bleeding", rAve.x, rAve.y, rAve.z,
             ia.x, ia.y, ia.z, result.lights.size());
  if (result.ambient.reflectanceClamped)
    fmt::print(stderr, "note: the average reflectance reaches 1; it was clamped to 0.999 (I_a would be infinite)\n");
  writeOutputs(o, image, stats, context, loaded,
               {{"method", o.method}, {"dmax", result.dMax}, {"rho", o.rho}, {"tau", settings.tau},
                {"sampling", o.sampling}, {"colour_bleeding", !o.noBleed}, {"max_depth", settings.maxDepth},
                {"shadow_rays_per_hit", settings.shadowRays}, {"obscurance_rays_per_hit", settings.obscuranceRays},
                {"r_ave", {rAve.x, rAve.y, rAve.z}}, {"ambient_intensity", {ia.x, ia.y, ia.z}},
                {"lights", result.lights.names}});
}

} // namespace

void addRenderCommand(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render a glTF scene headless to EXR (all AOVs) or PNG");
  cmd->add_option("scene", options->scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
  cmd->add_option("-o,--output", options->output, "output image, .exr (AOV layers) or .png (tonemapped)")->required();
  cmd->add_option("--width", options->width, "image width in pixels (default: 512 on the long side)")
      ->check(CLI::Range(1u, 16384u));
  cmd->add_option("--height", options->height, "image height in pixels")->check(CLI::Range(1u, 16384u));
  cmd->add_option("--spp", options->spp, "primary samples per pixel")->check(CLI::Range(1u, 1u << 20));
  cmd->add_option("--seed", options->seed, "random seed (same seed, same image)");
  cmd->add_option("--camera", options->camera, "index of the glTF camera to use (default: the first)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--aov", options->aovs, "AOV(s) to write; the first goes to PNG (default: all / preview)");
  cmd->add_option("--exposure", options->exposure, "PNG exposure in stops");
  cmd->add_option("--metrics", options->metrics, "write device, scene, BVH and per-pass figures as JSON");
  cmd->add_option("--method", options->method, "obscurance (ray-traced obscurances) or pathtrace (the reference)")
      ->check(CLI::IsMember({"obscurance", "pathtrace"}));
  cmd->add_option("--max-depth", options->obscurance.maxDepth,
                  "path depth in scattering vertices (specular paths; path tracing), default 6")
      ->check(CLI::Range(1u, 1024u));
  cmd->add_option("--shadow-rays", options->obscurance.shadowRays, "shadow rays per hit (N_s)")
      ->check(CLI::Range(0u, 1024u));
  cmd->add_option("--obs-rays", options->obscurance.obscuranceRays, "obscurance rays per hit (N_obs)")
      ->check(CLI::Range(0u, 1024u));
  cmd->add_option("--rho", options->rho, "rho(d): sqrt (the paper's), exp, ao")->check(CLI::IsMember({"sqrt", "exp", "ao"}));
  cmd->add_option("--tau", options->obscurance.tau, "tau of --rho exp")->check(CLI::PositiveNumber);
  cmd->add_option("--dmax", options->dMax, "dmax in scene units (default: 1/4 of the largest bounding-box extent)")
      ->each([options](const std::string&) { options->dMaxGiven = true; });
  cmd->add_option("--sampling", options->sampling, "obscurance rays: systematic (default) or random")
      ->check(CLI::IsMember({"systematic", "random"}));
  cmd->add_flag("--no-bleed", options->noBleed, "grey obscurance W instead of colour bleeding W_c");
  addDeviceOptions(*cmd, options->device);
  cmd->callback([options] { runRender(*options); });
}

} // namespace obscura::app
