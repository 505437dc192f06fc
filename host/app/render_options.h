// render_options.h — the options of a render that `render` and `relight SCENE` share: image size,
// samples, camera, method and the obscurance parameters, and the settings made from them.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/commands.h"
#include "app/scene_setup.h"
#include "render/method.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "scene/scene.h"

namespace obscura::app {

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
  render::Method method = render::Method::Obscurance;
  std::string saveState;
  // The obscurance method's settings, the named options (--rho, --sampling, --vertex-rays,
  // --shadow-sampling, --light-sampling, --ambient, --dirty-test) parsed straight into them;
  // obscuranceSettings() adds the size, camera and samples.
  render::ObscuranceSettings obscurance;
  bool noBleed = false;
  float dMax = 0.0f;
  bool dMaxGiven = false;
  std::string lightGroups = "node";
  std::vector<float> background; // R,G,B radiance of the sky; empty: none
  bool denoise = false;          // render only: the denoised combined image too (render/denoise/)
  // render only: paths per pixel whose filtered difference corrects the frame (render/correction/):
  // "auto" (PathCorrection::defaultPaths of --spp) or a count, 0 for none; correctionPaths() reads it
  std::string pathCorrection = "auto";
  // render only: a farm's part (host/farm/part.h): samples "A:B" of --spp and tile "I/T"; empty:
  // the whole frame.
  std::string partSamples, partTile;
  DeviceOptions device;
};

// Registers the shared options on `cmd` (not the scene or the output, which each command names).
void addRenderOptions(CLI::App& cmd, RenderOptions& o);

// The defaults of a still image (`obscura render`, Python's obscura.render), set before
// addRenderOptions: the seen I_a, the least biased for one camera (converge measures with it).
// The window and edit sessions keep ObscuranceSettings' reached I_a: they move the camera or edit
// the scene, and the seen fit belongs to one camera and one scene.
void useStillImageDefaults(RenderOptions& o);

// --emission-samples auto|auto:K|K (and converge's --pt-emission-samples): `auto` (the default)
// sets gpu::kEdgeEmissionSamples rays where an emitter's edge crosses the pixel and the primary ray
// elsewhere, auto:K K rays there; a number K, K rays in every pixel (1: the primary ray alone).
// `what` names the renderer.
void addEmissionSamplesOption(CLI::App& cmd, const std::string& name, std::uint32_t& samples, bool& atEdges,
                              const std::string& what);
// InputError for option values CLI11's checks cannot see (a non-finite --dmax).
void checkRenderOptions(const RenderOptions& o);
// The camera `index` of the scene (-1: the first, or the default camera when it has none).
scene::Camera chooseCamera(const scene::Scene& scene, int index);
// Fills a missing width or height from the camera's aspect (512 on the long side when both are).
void chooseSize(RenderOptions& o, const scene::Camera& camera);
// The obscurance renderer's settings from the options, for `camera` at the chosen size.
render::ObscuranceSettings obscuranceSettings(const RenderOptions& o, const scene::Camera& camera);
// The path tracer's settings for the image `settings` makes (--method pathtrace): its size, rows,
// samples, seed, camera, depth, light sampling and camera rays for the seen emission.
render::PathTraceSettings pathTraceSettings(const render::ObscuranceSettings& settings);
// Gives the loaded scene the --background sky (after loadScene, before the lights are built).
void applyBackground(const RenderOptions& o, LoadedScene& loaded);
// InputError unless --background's R, G, B are finite and >= 0.
void checkBackground(const std::vector<float>& background);
// Warns (stderr) when no light of the scene emits anything: the image would be black but for
// seen emission, and a user deserves to know why.
void warnIfUnlit(const LoadedScene& loaded);

} // namespace obscura::app
