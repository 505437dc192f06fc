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
#include "app/render_options.h"
#include "app/render_part.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "gpu/buffer.h"
#include "io/image_io.h"
#include "render/aovs.h"
#include "render/denoise/denoiser.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "relight/relight_state.h"

namespace obscura::app {
namespace {

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
// `display`, when given, is the GPU-tonemapped combined image, written as the PNG of `combined`.
void writeOutputs(const RenderOptions& o, const io::Image& image, const render::RenderStats& stats,
                  const gpu::Context& context, const LoadedScene& loaded, const nlohmann::json& method,
                  const std::vector<std::uint32_t>* display = nullptr) {
  for (const auto& note : stats.notes) fmt::print(stderr, "note: {}\n", note);
  if (stats.truncatedTraversals > 0)
    throw DeviceError(fmt::format("{} traversals ran out of steps (kMaxTraversalSteps); the image would be wrong",
                                  stats.truncatedTraversals));

  io::Image selected = render::selectAovs(image, o.aovs);
  if (io::extensionOf(o.output) == "exr") {
    io::writeExr(o.output, selected);
  } else if (display && (o.aovs.empty() || o.aovs.front() == "combined" || o.aovs.front() == "denoised")) {
    io::writePngRgba8(o.output, image.width, image.height, *display);
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
  if (isPartRender(o)) {
    renderPart(o);
    return;
  }
  std::string ext = io::extensionOf(o.output);
  if (ext != "exr" && ext != "png")
    throw InputError(fmt::format("{}: the output must be .exr or .png", o.output));
  if (o.denoise && o.method == render::Method::PathTrace)
    throw InputError("--denoise with --method pathtrace: the denoiser filters the obscurance method's direct and "
                     "ambient terms divided by the albedo, which path tracing does not keep; use --method obscurance");
  static const std::vector<std::string> pathAovs = {"combined"};
  std::vector<std::string> known = o.method == render::Method::PathTrace ? pathAovs : render::obscuranceAovNames();
  if (o.denoise) known.push_back("denoised");
  for (const auto& aov : o.aovs)
    if (std::find(known.begin(), known.end(), aov) == known.end())
      throw InputError(fmt::format("--aov {}: unknown AOV (known: {}){}", aov, fmt::join(known, ", "),
                                   aov == "denoised" ? "; it needs --denoise" : ""));
  checkRenderOptions(o);
  if (!o.metrics.empty()) checkWritable(o.metrics);

  LoadedScene loaded = loadScene(o.scenePath, o.lightGroups, std::nullopt);
  applyBackground(o, loaded);
  scene::Camera camera = chooseCamera(loaded.scene, o.camera);
  chooseSize(o, camera);
  warnIfUnlit(loaded);

  gpu::Context context(o.device.contextOptions());
  fmt::print(stderr, "device: {} ({})\n", context.info().name, context.info().driver);
  buildTreeFor(loaded, context);
  fmt::print(stderr, "{}\n", sceneSummary(loaded));

  render::ObscuranceSettings settings = obscuranceSettings(o, camera);
  settings.editableGeometry = false; // rendered, written out, done
  const bool tty = ::isatty(STDERR_FILENO);
  const std::uint64_t raysPerSample = std::uint64_t(o.width) * o.height *
                                      (1 + settings.shadowRays + settings.obscuranceRays);
  const render::ProgressFn progress =
      tty ? render::ProgressFn([&](auto d, auto t, auto s) { printProgress(d, t, s, raysPerSample); })
          : render::ProgressFn();
  if (o.method == render::Method::PathTrace) {
    if (!o.saveState.empty())
      throw InputError("--save-state: only the obscurance method keeps per-light transport (--method obscurance)");
    render::PathTraceSettings pt{.width = o.width, .height = o.height, .spp = o.spp, .seed = o.seed,
                                 .camera = camera, .maxDepth = settings.maxDepth,
                                 .lightSampling = settings.lightSampling,
                                 .emissionSamples = settings.emissionSamples};
    render::PathTracer tracer(context, loaded.scene, loaded.bvh, pt);
    tracer.render(progress);
    writeOutputs(o, tracer.image(), tracer.stats(), context, loaded,
                 {{"method", nameString(render::kMethodNames, o.method)}, {"max_depth", pt.maxDepth}, {"emission_samples", pt.emissionSamples}});
    return;
  }
  // Only what the output shows is kept: a PNG of combined needs neither the primary AOVs nor the
  // other composed ones (a 4K frame then fits lavapipe's 2 GiB).
  const bool exr = io::extensionOf(o.output) == "exr";
  const std::vector<std::string> wanted = o.aovs.empty() ? (exr ? render::obscuranceAovNames()
                                                                : std::vector<std::string>{"combined"})
                                                         : o.aovs;
  // The denoiser's guides and terms are the primary and composed AOVs.
  const bool keepAll = o.denoise;
  const auto& primaryNames = render::aovNames();
  settings.primaryAovs = keepAll || std::any_of(wanted.begin(), wanted.end(), [&](const std::string& a) {
    return a != "emission" && std::find(primaryNames.begin(), primaryNames.end(), a) != primaryNames.end();
  });
  settings.composedAovs = keepAll || std::any_of(wanted.begin(), wanted.end(), [](const std::string& a) { return a != "combined"; });
  render::ObscuranceRenderer renderer(context, loaded.scene, loaded.bvh, settings);
  renderer.reset();
  renderer.iterate(settings.spp, progress);
  renderer.compose(o.exposure);
  const render::RenderStats stats = renderer.stats();
  io::Image image = renderer.image();
  // The EXR carries one layer per light group (light.<name>), so that a compositor can relight it.
  if (io::extensionOf(o.output) == "exr" && o.aovs.empty()) appendChannels(image, renderer.lightLayers());
  std::vector<std::uint32_t> display = renderer.display();
  nlohmann::json denoiseJson = nullptr;
  if (o.denoise) {
    // One frame: the renderer's samples alone (no history), filtered; the EXR gets it as the
    // `denoised` layer beside the rest (combined stays the sum of the light layers), the PNG of
    // combined shows it.
    render::Denoiser denoiser(context, renderer);
    denoiser.denoise(renderer, o.exposure);
    io::Image denoised = denoiser.image();
    denoised.channels = render::aovChannels("denoised");
    appendChannels(image, denoised);
    display = denoiser.display();
    denoiseJson = {{"gpu_ms", denoiser.lastGpuMs()}, {"passes_gpu_ms", denoiser.lastPassMs()},
                   {"iterations", denoiser.settings().iterations}};
    std::string passes;
    for (const auto& [name, ms] : denoiser.lastPassMs()) passes += fmt::format("{}{} {:.1f}", passes.empty() ? "" : ", ", name, ms);
    fmt::print(stderr, "denoise: {:.1f} ms GPU ({})\n", denoiser.lastGpuMs(), passes);
  }
  const glm::vec3 ia = renderer.ambientIntensity(), rAve = renderer.ambient().averageReflectance;
  const glm::vec3 iaGlobal = renderer.ambient().globalIntensity(renderer.emissions());
  fmt::print(stderr, "obscurance: dmax {:.4g}, rho {}, {} sampling, {}; R_ave ({:.4f}, {:.4f}, {:.4f}), "
                     "I_a ({:.4g}, {:.4g}, {:.4g}) from {} (the paper's whole-scene formula: ({:.4g}, {:.4g}, {:.4g})); "
                     "{} lights; frame in {} band(s)\n",
             renderer.dMax(), nameOf(render::kRhoKindNames, settings.rho),
             nameOf(render::kObscuranceSamplingNames, settings.systematic), o.noBleed ? "grey" : "colour bleeding",
             rAve.x, rAve.y, rAve.z, ia.x, ia.y, ia.z,
             settings.ambient == render::AmbientModel::Global ? "the whole scene"
             : settings.ambient == render::AmbientModel::Seen
                 ? "the surfaces the lights reach, first bounce fitted to the camera's view"
                 : "the surfaces the lights reach",
             iaGlobal.x, iaGlobal.y, iaGlobal.z, renderer.lights().size(), renderer.layout().bandCount());
  if (settings.secondaryReflectors > 0.0f)
    fmt::print(stderr, "secondary reflectors: {} of {} triangles marked (threshold {:g} x each light's mean direct "
                       "irradiance)\n",
               renderer.secondaryReflectors(), loaded.scene.triangles.size(), settings.secondaryReflectors);
  if (renderer.ambient().reflectanceClamped)
    fmt::print(stderr, "note: the average reflectance reaches 1; it was clamped to 0.999 (I_a would be infinite)\n");
  if (!o.saveState.empty()) relight::saveState(o.saveState, renderer, o.scenePath);
  writeOutputs(o, image, stats, context, loaded,
               {{"method", nameString(render::kMethodNames, o.method)}, {"dmax", renderer.dMax()},
                {"rho", nameString(render::kRhoKindNames, settings.rho)}, {"tau", settings.tau},
                {"sampling", nameString(render::kObscuranceSamplingNames, settings.systematic)},
                {"colour_bleeding", !o.noBleed}, {"max_depth", settings.maxDepth},
                {"vertex_rays", nameString(render::kVertexRaysNames, settings.vertexRaysByThroughput)},
                {"light_sampling", nameString(render::kLightSamplingNames, settings.lightSampling)},
                {"ambient", nameString(render::kAmbientModelNames, settings.ambient)},
                {"secondary_reflectors", settings.secondaryReflectors},
                {"secondary_reflector_triangles", renderer.secondaryReflectors()},
                {"i_a", {ia.x, ia.y, ia.z}}, {"i_a_global", {iaGlobal.x, iaGlobal.y, iaGlobal.z}},
                {"shadow_rays_per_hit", settings.shadowRays}, {"obscurance_rays_per_hit", settings.obscuranceRays},
                {"emission_samples", settings.emissionSamples}, {"r_ave", {rAve.x, rAve.y, rAve.z}}, {"ambient_intensity", {ia.x, ia.y, ia.z}},
                {"lights", renderer.lights().names}, {"bands", renderer.layout().bandCount()},
                {"denoise", denoiseJson}},
               &display);
}

} // namespace

void addRenderCommand(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render a glTF scene headless to EXR (all AOVs) or PNG");
  cmd->add_option("scene", options->scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
  cmd->add_option("-o,--output", options->output, "output image, .exr (AOV layers) or .png (tonemapped)")->required();
  addRenderOptions(*cmd, *options);
  cmd->add_option("--aov", options->aovs, "AOV(s) to write; the first goes to PNG (default: all / preview)");
  cmd->add_option("--exposure", options->exposure, "PNG exposure in stops");
  cmd->add_option("--metrics", options->metrics, "write device, scene, BVH and per-pass figures as JSON");
  cmd->add_option("--save-state", options->saveState,
                  "write the relighting state to this folder (per-light transport as EXR layers + JSON), for "
                  "'obscura relight DIR'");
  cmd->add_flag("--denoise", options->denoise,
                 "denoise the obscurance frame (render/denoise/: demodulated direct and ambient terms, edge-aware "
                 "a-trous filter): the PNG of combined shows it, the EXR gets a `denoised` layer");
  cmd->add_option("--samples", options->partSamples,
                  "A:B: render only samples A (included) to B (excluded) of --spp, as a part of a farm render "
                  "(written as sums to -o part.exr; 'obscura merge' adds the parts up; tools/farm/)");
  cmd->add_option("--tile", options->partTile,
                  "I/T: render only the I-th (0-based) of T strips of whole rows, as a part of a farm render "
                  "(with or without --samples)");
  addDeviceOptions(*cmd, options->device);
  cmd->callback([options] { runRender(*options); });
}

} // namespace obscura::app
