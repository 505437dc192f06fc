// obscura view SCENE [render options] [--frames N --screenshot out.png --script events.json ...]
// The real-time window (host/window/viewer.h): progressive obscurances with live light, camera and
// object edits. Needs a window system (X11, Wayland, or Xvfb); without one it says so and exits 3.
// `--offscreen` runs the same frame loop with no window system (window/offscreen_target.h), to the
// end of --frames or of the script: benchmarks and tests where there is no display.
#include <fmt/format.h>

#include "app/commands.h"
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "render/aovs.h"
#include "window/control_panel.h"
#include "window/offscreen_target.h"
#include "window/viewer.h"
#include "window/window_target.h"

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
  bool offscreen = false;
  std::string aov = "combined";
};

// `--offscreen` has no window and no person: it needs an end, and refuses what only a window has.
// Runs before the scene is loaded, so a mistake costs nothing.
void checkOffscreen(ViewOptions& o, const window::EventScript& script) {
  if (o.frames == 0 && script.length() == 0)
    throw InputError("--offscreen needs an end: --frames N, or a --script (the run ends after its last event)");
  if (o.screenshotUi) throw InputError("--screenshot-ui: --offscreen draws no panel");
  for (const auto& e : script.events())
    if (e.kind == window::ScriptEvent::Kind::Window && e.text != "close")
      throw InputError(fmt::format("{}: the window event '{}' at frame {} needs a window (not --offscreen)", o.script,
                                   e.text, e.frame));
  if (o.frames == 0) o.frames = script.length();
}

void runView(ViewOptions& o, bool sppGiven) {
  RenderOptions& r = o.render;
  checkRenderOptions(r);
  const std::string shot = io::extensionOf(o.screenshot);
  window::EventScript script;
  if (!o.script.empty()) script = window::EventScript(o.script); // checked before a window opens
  if (o.offscreen) checkOffscreen(o, script);
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
  config.script = std::move(script);

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
  config.panel = config.panel && !o.offscreen;
  std::unique_ptr<window::FrameTarget> target;
  if (o.offscreen) target = std::make_unique<window::OffscreenTarget>();
  else target = std::make_unique<window::WindowTarget>(static_cast<int>(config.obscurance.width),
                                                      static_cast<int>(config.obscurance.height), config.title);
  window::Viewer viewer(std::move(target), r.device.contextOptions(), std::move(loaded.scene), std::move(loaded.bvh),
                        std::move(config));
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
  cmd->add_option("--log", options->log,
                  "write one JSON line per frame (samples, restarts, pixels retraced, rays, the actions applied, "
                  "wall_ms: the whole frame on the host's clock, frame_gpu_ms: its GPU timestamps)");
  cmd->add_option("--view", options->view, "start from a view saved with F5 (a glTF-style camera JSON)");
  cmd->add_option("--view-file", options->viewFile, "where F5 saves and F9 loads the view (default view.json)");
  cmd->add_option("--aov", options->aov, "the AOV shown first (default combined)");
  cmd->add_option("--exposure", options->render.exposure, "exposure in stops");
  cmd->add_flag("--no-denoise", options->noDenoise, "show the frames as accumulated (the denoiser is on by default)");
  cmd->add_flag("--no-panel", options->noPanel, "no panel over the image");
  cmd->add_flag("--offscreen", options->offscreen,
                "the same frame loop, actions and script without a window system (no DISPLAY needed): nothing is "
                "presented and there is no panel (--screenshot-ui and window events other than close are refused); "
                "runs --frames N or to the script's last event; the frame is read back only for screenshots");
  addDeviceOptions(*cmd, options->render.device);
  cmd->callback([options, cmd] { runView(*options, cmd->count("--spp") > 0); });
}

} // namespace obscura::app
