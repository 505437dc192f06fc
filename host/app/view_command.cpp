// obscura view SCENE [render options] [--frames N --screenshot out.png --script events.json ...]
// The real-time window (host/window/viewer.h): progressive obscurances with live light, camera and
// object edits. Needs a window system (X11, Wayland, or Xvfb); without one it says so and exits 3.
#include <fmt/format.h>

#include "app/commands.h"
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "render/aovs.h"
#include "window/control_panel.h"
#include "window/viewer.h"

namespace obscura::app {
namespace {

struct ViewOptions {
  RenderOptions render;
  std::size_t frames = 0;
  std::string screenshot;
  bool screenshotUi = false;
  std::string script;
  std::string log;
  std::string view;
  std::string viewFile = "view.json";
  bool noDenoise = false;
  bool noPanel = false;
  std::string aov = "combined";
};

void runView(ViewOptions& o, bool sppGiven) {
  RenderOptions& r = o.render;
  checkRenderOptions(r);
  const std::string shot = io::extensionOf(o.screenshot);
  if (!o.screenshot.empty() && shot != "png" && shot != "exr")
    throw InputError(fmt::format("--screenshot {}: a screenshot is .png (as shown) or .exr (linear AOVs)", o.screenshot));
  if (o.screenshotUi && shot == "exr")
    throw InputError("--screenshot-ui: the panel is only in PNG screenshots");
  if (!o.screenshot.empty() && o.frames == 0)
    throw InputError("--screenshot needs --frames N (the frame to capture is the last one)");
  if (o.screenshotUi && o.noPanel) throw InputError("--screenshot-ui with --no-panel: there is no panel to include");
  const auto& names = render::obscuranceAovNames();
  if (o.aov != "combined" && std::find(names.begin(), names.end(), o.aov) == names.end())
    throw InputError(fmt::format("--aov {}: unknown AOV (known: combined, {})", o.aov, fmt::join(names, ", ")));
  window::ViewerConfig config;
  if (!o.script.empty()) config.script = window::EventScript(o.script); // checked before a window opens

  LoadedScene loaded = loadScene(r.scenePath, r.lightGroups);
  applyBackground(r, loaded);
  scene::Camera camera = o.view.empty() ? chooseCamera(loaded.scene, r.camera) : window::loadView(o.view);
  if (r.width == 0 && r.height == 0) {
    r.width = 640;
    r.height = 480;
  }
  chooseSize(r, camera);
  fmt::print(stderr, "{}\n", sceneSummary(loaded));
  warnIfUnlit(loaded);

  config.title = fmt::format("obscura — {}", r.scenePath);
  config.obscurance = obscuranceSettings(r, camera);
  if (!sppGiven) config.obscurance.spp = 1024;
  config.method = r.method;
  config.exposure = r.exposure;
  config.aov = o.aov;
  config.denoise = !o.noDenoise;
  config.panel = !o.noPanel;
  config.frames = o.frames;
  config.screenshot = o.screenshot;
  config.screenshotUi = o.screenshotUi;
  config.log = o.log;
  config.viewFile = o.viewFile;
  window::Viewer viewer(r.device.contextOptions(), std::move(loaded.scene), std::move(loaded.bvh), std::move(config));
  viewer.run();
}

} // namespace

void addViewCommand(CLI::App& app) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", fmt::format("Open a window: progressive obscurances with live light, camera and object edits.\n{}",
                          window::viewerControlsHelp()));
  cmd->add_option("scene", options->render.scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
  addRenderOptions(*cmd, options->render);
  cmd->add_option("--frames", options->frames, "show N frames, then exit (default: until the window closes)");
  cmd->add_option("--screenshot", options->screenshot, "write the last frame as shown: PNG (tonemapped, without the panel) or EXR (linear AOVs)");
  cmd->add_flag("--screenshot-ui", options->screenshotUi, "screenshots include the panel");
  cmd->add_option("--script", options->script, "replay timed input from a JSON list of events (format: README, host/window/event_script.h)");
  cmd->add_option("--log", options->log, "write one JSON line per frame (samples, restarts, pixels retraced, rays, ms)");
  cmd->add_option("--view", options->view, "start from a view saved with F5 (a glTF-style camera JSON)");
  cmd->add_option("--view-file", options->viewFile, "where F5 saves and F9 loads the view (default view.json)");
  cmd->add_option("--aov", options->aov, "the AOV shown first (default combined)");
  cmd->add_option("--exposure", options->render.exposure, "exposure in stops");
  cmd->add_flag("--no-denoise", options->noDenoise, "show the frames as accumulated (the denoiser is on by default)");
  cmd->add_flag("--no-panel", options->noPanel, "no panel over the image");
  addDeviceOptions(*cmd, options->render.device);
  cmd->callback([options, cmd] { runView(*options, cmd->count("--spp") > 0); });
}

} // namespace obscura::app
