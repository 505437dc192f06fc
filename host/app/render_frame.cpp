#include "app/render_frame.h"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

#include "core/error.h"
#include "render/aovs.h"
#include "render/correction/path_correction.h"
#include "render/denoise/denoiser.h"
#include "render/path_tracer.h"

namespace obscura::app {

std::uint32_t correctionPaths(const RenderOptions& o) {
  if (o.pathCorrection == "auto")
    return o.method == render::Method::PathTrace || o.denoise ? 0u : render::PathCorrection::defaultPaths(o.spp);
  std::uint32_t paths = 0;
  const char* end = o.pathCorrection.data() + o.pathCorrection.size();
  const auto [last, ec] = std::from_chars(o.pathCorrection.data(), end, paths);
  if (ec != std::errc() || last != end || paths > (1u << 20))
    throw InputError(fmt::format("--pt-correction {}: expected auto or a number of paths per pixel (0 to {})",
                                 o.pathCorrection, 1u << 20));
  if (paths > 0 && o.method == render::Method::PathTrace)
    throw InputError("--pt-correction with --method pathtrace: the paths correct the obscurance frame; use --method "
                     "obscurance");
  if (paths > 0 && o.denoise)
    throw InputError("--pt-correction with --denoise: the correction's filter already takes the paths' noise; use one");
  return paths;
}

void checkFrameOptions(const RenderOptions& o) {
  if (o.denoise && o.method == render::Method::PathTrace)
    throw InputError("--denoise with --method pathtrace: the denoiser filters the obscurance method's direct and "
                     "ambient terms divided by the albedo, which path tracing does not keep; use --method obscurance");
  static const std::vector<std::string> pathAovs = {"combined"};
  std::vector<std::string> known = o.method == render::Method::PathTrace ? pathAovs : render::obscuranceAovNames();
  const std::uint32_t paths = correctionPaths(o);
  if (o.denoise) known.push_back("denoised");
  if (paths > 0) known.push_back("corrected");
  for (const auto& aov : o.aovs)
    if (std::find(known.begin(), known.end(), aov) == known.end())
      throw InputError(fmt::format("--aov {}: unknown AOV (known: {}){}", aov, fmt::join(known, ", "),
                                   aov == "denoised"    ? "; it needs --denoise"
                                   : aov == "corrected" ? "; it needs --pt-correction N (or more than 8 --spp)"
                                                        : ""));
  checkRenderOptions(o);
}

nlohmann::json statsJson(const render::RenderStats& stats) {
  nlohmann::json passes = nlohmann::json::object();
  double totalMs = 0.0;
  std::uint64_t totalRays = 0;
  for (const auto& [name, pass] : stats.passes) {
    passes[name] = {{"gpu_ms", pass.gpuMs}, {"rays", pass.rays},
                    {"mrays_per_s", pass.gpuMs > 0 ? static_cast<double>(pass.rays) / (pass.gpuMs * 1e3) : 0.0}};
    totalMs += pass.gpuMs;
    totalRays += pass.rays;
  }
  return {{"passes", passes},
          {"gpu_ms", totalMs},
          {"rays", totalRays},
          {"mrays_per_s", totalMs > 0 ? static_cast<double>(totalRays) / (totalMs * 1e3) : 0.0},
          {"wall_s", stats.wallSeconds},
          {"device_bytes", stats.deviceBytes},
          {"truncated_traversals", stats.truncatedTraversals}};
}

void checkTraversals(const render::RenderStats& stats) {
  if (stats.truncatedTraversals > 0)
    throw DeviceError(fmt::format("{} traversals ran out of steps (kMaxTraversalSteps); the image would be wrong",
                                  stats.truncatedTraversals));
}

namespace {

RenderedFrame pathTrace(const RenderOptions& o, const scene::Scene& scene, const bvh::Bvh& bvh, const gpu::Context& context,
                        const render::ObscuranceSettings& settings, const render::ProgressFn& progress) {
  const render::PathTraceSettings pt = pathTraceSettings(settings);
  render::PathTracer tracer(context, scene, bvh, pt);
  tracer.render(progress);
  RenderedFrame frame;
  frame.image = tracer.image();
  frame.stats = tracer.stats();
  frame.method = {{"method", nameString(render::kMethodNames, o.method)}, {"max_depth", pt.maxDepth},
                  {"emission_samples", pt.emissionSamples}, {"emission_at_edges", pt.emissionAtEdges}};
  return frame;
}

} // namespace

void addFrameOptions(CLI::App& cmd, RenderOptions& o) {
  cmd.add_option("--aov", o.aovs, "AOV(s) to write; the first goes to PNG (default: all / preview)");
  cmd.add_option("--exposure", o.exposure, "PNG exposure in stops");
  cmd.add_flag("--denoise", o.denoise,
               "denoise the obscurance frame (render/denoise/: demodulated direct and ambient terms, edge-aware "
               "a-trous filter; at 1 spp, the pixels an edge crosses resolved from camera rays of their own): the PNG "
               "of combined shows it, the EXR gets a `denoised` layer");
  cmd.add_option("--pt-correction", o.pathCorrection,
                 "auto|N: trace N paths per pixel too and correct the obscurance frame by their difference to it, "
                 "filtered along surfaces (render/correction/): the ambient model's bias goes, the direct light, "
                 "contact shadows and textures stay the obscurances'; with more paths the filter narrows and the "
                 "frame converges to path tracing's. The PNG of combined shows it, the EXR gets a `corrected` "
                 "layer (not relightable: the paths have no per-light transport). auto (default): none up to the "
                 "paper's budget of 8 spp, past it one path for each further sample, at least 4 (--spp 16: 8 "
                 "paths), so a longer render keeps approaching path tracing's image instead of stopping at the "
                 "obscurances' bias; never with --denoise or in a farm's part (--samples, --tile: merged parts "
                 "are the obscurances' sums). The window does not correct its frames: they follow a moving "
                 "camera at one sample each. 0: none")
      ->default_str("auto");
}

RenderedFrame renderFrame(RenderOptions& o, const scene::Scene& scene, const bvh::Bvh& bvh, const gpu::Context& context,
                          const FrameOutputs& outputs, const render::ProgressFn& progress) {
  checkFrameOptions(o);
  const scene::Camera camera = chooseCamera(scene, o.camera);
  chooseSize(o, camera);
  render::ObscuranceSettings settings = obscuranceSettings(o, camera);
  settings.editableGeometry = false; // rendered, handed over, done
  if (o.method == render::Method::PathTrace) {
    if (outputs.state)
      throw InputError("--save-state: only the obscurance method keeps per-light transport (--method obscurance)");
    return pathTrace(o, scene, bvh, context, settings, progress);
  }
  // Only what the output shows is kept: a PNG of combined needs neither the primary AOVs nor the
  // other composed ones (a 4K frame then fits lavapipe's 2 GiB).
  const std::vector<std::string> wanted =
      o.aovs.empty() ? (outputs.allAovs ? render::obscuranceAovNames() : std::vector<std::string>{"combined"}) : o.aovs;
  // The denoiser's guides and terms are the primary and composed AOVs.
  // The paths correct combined: none where the output shows no combined image.
  const bool showsCombined = std::any_of(wanted.begin(), wanted.end(), [](const std::string& a) {
    return a == "combined" || a == "corrected";
  });
  const std::uint32_t pathsWanted = showsCombined ? correctionPaths(o) : 0u;
  const bool keepAll = o.denoise || pathsWanted > 0;
  const auto& primaryNames = render::aovNames();
  settings.primaryAovs = keepAll || std::any_of(wanted.begin(), wanted.end(), [&](const std::string& a) {
    return a != "emission" && std::find(primaryNames.begin(), primaryNames.end(), a) != primaryNames.end();
  });
  settings.composedAovs = keepAll || std::any_of(wanted.begin(), wanted.end(), [](const std::string& a) { return a != "combined"; });
  render::ObscuranceRenderer renderer(context, scene, bvh, settings);
  renderer.reset();
  renderer.iterate(settings.spp, progress);
  renderer.compose(o.exposure);
  RenderedFrame frame;
  frame.stats = renderer.stats();
  frame.image = renderer.image();
  // One layer per light group (light.<name>), so that a compositor can relight the frame.
  if (outputs.lightLayers) appendChannels(frame.image, renderer.lightLayers());
  if (outputs.state) frame.state = relight::currentState(renderer, o.scenePath);
  frame.display = renderer.display();
  nlohmann::json denoiseJson = nullptr;
  if (o.denoise) {
    // One frame: the renderer's samples alone (no history), filtered; the image gets it as the
    // `denoised` layer beside the rest (combined stays the sum of the light layers), the display
    // shows it.
    render::Denoiser denoiser(context, renderer);
    denoiser.denoise(renderer, o.exposure);
    io::Image denoised = denoiser.image();
    denoised.channels = render::aovChannels("denoised");
    appendChannels(frame.image, denoised);
    frame.display = denoiser.display();
    denoiseJson = {{"gpu_ms", denoiser.lastGpuMs()}, {"passes_gpu_ms", denoiser.lastPassMs()},
                   {"iterations", denoiser.settings().iterations}};
    std::string passes;
    for (const auto& [name, ms] : denoiser.lastPassMs()) passes += fmt::format("{}{} {:.1f}", passes.empty() ? "" : ", ", name, ms);
    frame.summary += fmt::format("denoise: {:.1f} ms GPU ({})\n", denoiser.lastGpuMs(), passes);
  }
  nlohmann::json correctionJson = nullptr;
  if (pathsWanted > 0) {
    // The paths with the path tracer's own seed stream (another seed than the obscurance frame's).
    render::PathTraceSettings pt = pathTraceSettings(settings);
    pt.spp = pathsWanted;
    pt.seed = settings.seed + 0x9e3779b9u;
    render::PathTracer paths(context, scene, bvh, pt);
    paths.render();
    render::PathCorrection correction(context, renderer, paths);
    correction.correct(renderer, paths);
    io::Image corrected = correction.image();
    corrected.channels = render::aovChannels("corrected");
    appendChannels(frame.image, corrected);
    frame.display.clear(); // the PNG tonemaps the corrected layer (render_command.cpp)
    const render::RenderStats pathStats = paths.stats();
    for (const auto& [name, pass] : pathStats.passes) frame.stats.passes["correction." + name] = pass;
    for (const auto& [name, ms] : correction.lastPassMs()) frame.stats.passes["correction." + name] = {.gpuMs = ms};
    frame.stats.truncatedTraversals += pathStats.truncatedTraversals;
    for (const auto& note : pathStats.notes)
      if (std::find(frame.stats.notes.begin(), frame.stats.notes.end(), note) == frame.stats.notes.end())
        frame.stats.notes.push_back(note);
    const double pathMs = pathStats.passes.at("pathtrace").gpuMs;
    correctionJson = {{"paths", pathsWanted}, {"filter_iterations", correction.lastIterations()},
                      {"gpu_ms", correction.lastGpuMs()}, {"paths_gpu_ms", pathMs}};
    frame.summary += fmt::format("path-traced correction: {} paths per pixel in {:.1f} ms GPU, filter {} iterations "
                                 "in {:.1f} ms\n",
                                 pathsWanted, pathMs, correction.lastIterations(), correction.lastGpuMs());
  }
  const glm::vec3 ia = renderer.ambientIntensity(), rAve = renderer.ambient().averageReflectance;
  const glm::vec3 iaGlobal = renderer.ambient().globalIntensity(renderer.emissions());
  frame.summary += fmt::format(
      "obscurance: dmax {:.4g}, rho {}, {} sampling, {}; R_ave ({:.4f}, {:.4f}, {:.4f}), "
      "I_a ({:.4g}, {:.4g}, {:.4g}) from {} (the paper's whole-scene formula: ({:.4g}, {:.4g}, {:.4g})); "
      "{} lights; frame in {} band(s)",
      renderer.dMax(), nameOf(render::kRhoKindNames, settings.rho),
      nameOf(render::kObscuranceSamplingNames, settings.systematic), o.noBleed ? "grey" : "colour bleeding", rAve.x,
      rAve.y, rAve.z, ia.x, ia.y, ia.z,
      settings.ambient == render::AmbientModel::Global ? "the whole scene"
      : settings.ambient == render::AmbientModel::Seen
          ? "the surfaces the lights reach, first bounce fitted to the camera's view"
          : "the surfaces the lights reach",
      iaGlobal.x, iaGlobal.y, iaGlobal.z, renderer.lights().size(), renderer.layout().bandCount());
  if (settings.secondaryReflectors > 0.0f)
    frame.summary += fmt::format("\nsecondary reflectors: {} of {} triangles marked (threshold {:g} x each light's mean "
                                 "direct irradiance)",
                                 renderer.secondaryReflectors(), scene.triangles.size(),
                                 settings.secondaryReflectors);
  if (renderer.ambient().reflectanceClamped)
    frame.summary += "\nnote: the average reflectance reaches 1; it was clamped to 0.999 (I_a would be infinite)";
  frame.method = {{"method", nameString(render::kMethodNames, o.method)}, {"dmax", renderer.dMax()},
                  {"rho", nameString(render::kRhoKindNames, settings.rho)}, {"tau", settings.tau},
                  {"sampling", nameString(render::kObscuranceSamplingNames, settings.systematic)},
                  {"colour_bleeding", !o.noBleed}, {"max_depth", settings.maxDepth},
                  {"escapes", nameString(render::kEscapeModelNames, settings.escapes)},
                  {"dark_escapes", renderer.darkEscapes()},
                  {"vertex_rays", nameString(render::kVertexRaysNames, settings.vertexRaysByThroughput)},
                  {"light_sampling", nameString(render::kLightSamplingNames, settings.lightSampling)},
                  {"ambient", nameString(render::kAmbientModelNames, settings.ambient)},
                  {"secondary_reflectors", settings.secondaryReflectors},
                  {"secondary_reflector_triangles", renderer.secondaryReflectors()},
                  {"i_a", {ia.x, ia.y, ia.z}}, {"i_a_global", {iaGlobal.x, iaGlobal.y, iaGlobal.z}},
                  {"shadow_rays_per_hit", settings.shadowRays}, {"obscurance_rays_per_hit", settings.obscuranceRays},
                  {"emission_samples", settings.emissionSamples}, {"emission_at_edges", settings.emissionAtEdges},
                  {"r_ave", {rAve.x, rAve.y, rAve.z}},
                  {"ambient_intensity", {ia.x, ia.y, ia.z}}, {"lights", renderer.lights().names},
                  {"bands", renderer.layout().bandCount()}, {"denoise", denoiseJson}, {"path_correction", correctionJson}};
  return frame;
}

} // namespace obscura::app
