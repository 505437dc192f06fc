#include "app/render_options.h"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "app/named_option.h"
#include "core/error.h"

namespace obscura::app {

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

void addRenderOptions(CLI::App& cmd, RenderOptions& o) {
  cmd.add_option("--width", o.width, "image width in pixels (default: 512 on the long side)")
      ->check(CLI::Range(1u, 16384u));
  cmd.add_option("--height", o.height, "image height in pixels")->check(CLI::Range(1u, 16384u));
  const bool still = o.obscurance.ambient == render::AmbientModel::Seen; // useStillImageDefaults
  cmd.add_option("--spp", o.spp,
                 still ? "primary samples per pixel (past the paper's 8, the frame is corrected by paths as well: "
                         "--pt-correction)"
                       : "primary samples per pixel (never corrected by paths, as a still render past 8 spp is: "
                         "these frames follow a moving camera or edits, and the paths would be traced again for each)")
      ->check(CLI::Range(1u, 1u << 20));
  addEmissionSamplesOption(cmd, "--emission-samples", o.obscurance.emissionSamples, o.obscurance.emissionAtEdges,
                           "both methods");
  cmd.add_option("--seed", o.seed, "random seed (same seed, same image)");
  cmd.add_option("--camera", o.camera, "index of the glTF camera to use (default: the first)")
      ->check(CLI::NonNegativeNumber);
  addNamedOption(cmd, "--method", o.method, render::kMethodNames,
                 "obscurance (ray-traced obscurances) or pathtrace (the reference)");
  cmd.add_option("--max-depth", o.obscurance.maxDepth,
                  "path depth in scattering vertices (specular paths; path tracing), default 6")
      ->check(CLI::Range(1u, 1024u));
  cmd.add_option("--shadow-rays", o.obscurance.shadowRays,
                 "shadow rays per hit (N_s; default 8: the paper's ten rays per hit spent as 8 + 2 where the noise is; "
                 "5 + 5 is the paper's split)")
      ->check(CLI::Range(0u, 1024u));
  cmd.add_option("--obs-rays", o.obscurance.obscuranceRays, "obscurance rays per hit (N_obs; default 2)")
      ->check(CLI::Range(0u, 1024u));
  addNamedOption(cmd, "--vertex-rays", o.obscurance.vertexRaysByThroughput, render::kVertexRaysNames,
                 "shadow and obscurance rays at a specular path's vertices: throughput (default: N_s and N_obs scaled "
                 "by the path's throughput there, at least one each; the same mean for fewer rays) or per-hit (N_s and "
                 "N_obs at every vertex)");
  addNamedOption(cmd, "--rho", o.obscurance.rho, render::kRhoKindNames, "rho(d): sqrt (the paper's), exp, ao");
  cmd.add_option("--tau", o.obscurance.tau, "tau of --rho exp")->check(CLI::PositiveNumber);
  cmd.add_option("--dmax", o.dMax, "dmax in scene units (default: half the median distance between the surfaces the camera sees and "
                 "the next ones; 'obscura info' prints it)")
      ->each([&o](const std::string&) { o.dMaxGiven = true; });
  addNamedOption(cmd, "--sampling", o.obscurance.systematic, render::kObscuranceSamplingNames,
                 "obscurance rays: systematic (default) or random");
  cmd.add_flag("--no-bleed", o.noBleed, "grey obscurance W instead of colour bleeding W_c");
  addNamedOption(cmd, "--shadow-sampling", o.obscurance.shadowSampling, render::kShadowSamplingNames,
                 "selection (N_s rays per hit to lights chosen by power, default) or per-light (every light "
                 "alone, 4 rays per hit, up to 64 in penumbrae, one to a point light: relit images stay as clean as fresh ones)");
  addNamedOption(cmd, "--light-sampling", o.obscurance.lightSampling, render::kLightSamplingNames,
                 "how shadow rays pick lights (both methods): spatial (default: by importance at the point, "
                 "triangles by solid angle, MIS on glossy lobes) or area (the paper's: by power, uniform by area)");
  addNamedOption(cmd, "--ambient", o.obscurance.ambient, render::kAmbientModelNames,
                 fmt::format("which surfaces share a light's flux in I_a: reached (those its light reaches, directly or "
                             "after one bounce), seen (reached, with the first bounce fitted to what the light's landing "
                             "points send to the surfaces the camera sees: the least biased for one camera) or global "
                             "(the paper's: the whole scene). Default here: {}",
                             o.obscurance.ambient == render::AmbientModel::Seen
                                 ? "seen (a still image)"
                                 : "reached (the camera moves or the scene is edited, and the seen fit belongs to one "
                                   "camera and scene; a still render uses seen)"));
  addNamedOption(cmd, "--dirty-test", o.obscurance.dirtyTest, render::kDirtyTestNames,
                 "which pixels a geometry edit (relight --edits: move, remove, insert) retraces: bounds (those whose "
                 "rays' bounding boxes and shafts may meet the object's old or new place), probe (of those, the ones "
                 "one of whose rays does, found by replaying their rays) or auto (default: probe where rays may pass "
                 "anywhere: glossy surfaces' paths, obscurance rays traced past dmax (--escapes); else bounds)");
  addNamedOption(cmd, "--escapes", o.obscurance.escapes, render::kEscapeModelNames,
                 "what an obscurance ray that meets nothing within dmax brings: dark (it is traced on, and if it "
                 "leaves the scene it brings nothing: outside is only the background, a light of its own), ambient "
                 "(the paper's R_ave I_a, whatever lies beyond) or auto (default: dark where rays from the camera's "
                 "surfaces leave the scene, ambient in a closed one, where the extra rays would find a surface)");
  cmd.add_option("--secondary-reflectors", o.obscurance.secondaryReflectors,
                 "T: important secondary reflectors (the paper's future work): surfaces a light lights at least T "
                 "times its mean direct irradiance are marked, and an obscurance ray that lands on one traces the "
                 "direct light it reflects (default 0: off; 1 marks what is lit more than average)")
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--background", o.background,
                 "R,G,B: a constant sky radiance that rays leaving the scene see, one more light ('background') "
                 "that relighting can scale (default: none, black)")
      ->delimiter(',')
      ->expected(3);
  cmd.add_option("--light-groups", o.lightGroups,
                 "lights edited as one: node (one per emissive mesh node, default), material (one per emissive "
                 "material), or a JSON file {\"group\": [\"node\", ...]}");
}

void addEmissionSamplesOption(CLI::App& cmd, const std::string& name, std::uint32_t& samples, bool& atEdges,
                              const std::string& what) {
  cmd.add_option_function<std::string>(
         name,
         [name, &samples, &atEdges](const std::string& value) {
           // auto, auto:K (K rays at the edges) or K (everywhere).
           const bool edges = value.starts_with("auto");
           if (value == "auto") {
             samples = gpu::kEdgeEmissionSamples;
             atEdges = true;
             return;
           }
           const std::string count = edges ? (value.starts_with("auto:") ? value.substr(5) : std::string()) : value;
           std::uint32_t k = 0;
           const char* end = count.data() + count.size();
           const auto [last, error] = std::from_chars(count.data(), end, k);
           if (count.empty() || error != std::errc() || last != end || k < 1 || k > gpu::kMaxEmissionSamples)
             throw CLI::ValidationError(name, fmt::format("'{}' is neither auto, auto:K nor K, with K a count in 1..{}",
                                                          value, gpu::kMaxEmissionSamples));
           samples = k;
           atEdges = edges;
         },
         fmt::format("auto|auto:K|K: camera rays per sample for the emission the camera sees ({}). auto (default): "
                     "{} rays in the pixels an emitter's edge crosses (found by probing each pixel's corners once), "
                     "where a bright emitter's covered fraction sets the error, and the sample's own ray elsewhere; "
                     "auto:K: K rays there; K: K rays of their own (no shading) in every pixel, 1 = the sample's own ray",
                     what, gpu::kEdgeEmissionSamples))
      ->type_name("auto|auto:K|K");
}

void useStillImageDefaults(RenderOptions& o) { o.obscurance.ambient = render::AmbientModel::Seen; }

void applyBackground(const RenderOptions& o, LoadedScene& loaded) {
  if (o.background.empty()) return;
  loaded.scene.background = glm::vec3(o.background[0], o.background[1], o.background[2]);
}

void checkBackground(const std::vector<float>& background) {
  for (float c : background)
    if (!(std::isfinite(c) && c >= 0.0f))
      throw InputError(fmt::format("--background {}: each of R, G, B must be a finite radiance >= 0", c));
}

void checkRenderOptions(const RenderOptions& o) {
  checkBackground(o.background);
  if (!(std::isfinite(o.obscurance.secondaryReflectors) && o.obscurance.secondaryReflectors >= 0.0f))
    throw InputError(fmt::format("--secondary-reflectors {}: must be a finite threshold >= 0 (0: off)",
                                 o.obscurance.secondaryReflectors));
  if (o.obscurance.secondaryReflectors > 0.0f && o.obscurance.shadowSampling == render::ShadowSampling::PerLight)
    throw InputError("--secondary-reflectors with --shadow-sampling per-light: the reflectors choose among all lights "
                     "by importance, so each light's transport would depend on the others' power; use one or the other");
  if (o.dMaxGiven && !(std::isfinite(o.dMax) && o.dMax > 0.0f))
    throw InputError(fmt::format("--dmax {}: must be a finite positive distance in scene units", o.dMax));
}

render::ObscuranceSettings obscuranceSettings(const RenderOptions& o, const scene::Camera& camera) {
  render::ObscuranceSettings settings = o.obscurance;
  settings.width = o.width;
  settings.height = o.height;
  settings.spp = o.spp;
  settings.seed = o.seed;
  settings.camera = camera;
  settings.dMax = o.dMax;
  settings.colourBleeding = !o.noBleed;
  return settings;
}

render::PathTraceSettings pathTraceSettings(const render::ObscuranceSettings& settings) {
  return {.width = settings.width, .height = settings.height, .spp = settings.spp, .seed = settings.seed,
          .camera = settings.camera, .maxDepth = settings.maxDepth, .lightSampling = settings.lightSampling,
          .emissionSamples = settings.emissionSamples, .emissionAtEdges = settings.emissionAtEdges,
          .firstSample = settings.firstSample, .rows = settings.rows};
}

void warnIfUnlit(const LoadedScene& loaded) {
  const render::LightSet lights = render::buildLightSet(loaded.scene);
  if (lights.anySampled()) return;
  fmt::print(stderr,
             "warning: {} has no light that emits (no emissive material with emission > 0, no KHR_lights_punctual "
             "light, no --background): direct light and the obscurance term's I_a are 0, so the image is black but for "
             "what emits. Give it a sky with --background R,G,B, add a light to the scene, or relight it: obscura "
             "relight SCENE --edits EDITS.json with an add_light edit\n",
             loaded.scene.sourcePath);
}

} // namespace obscura::app
