// viewer.cpp — see viewer.h.
#include "window/viewer.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h> // the key codes alone: input arrives through the FrameTarget

#include "bvh/bvh.h"
#include "render/scene_data/scene_buffers.h"
#include "core/error.h"
#include "io/image_io.h"
#include "render/aovs.h"
#include "render/transport.h"
#include "scene/scene_edit.h"
#include "window/frame_presenter.h"
#include "window/ui_overlay.h"

namespace obscura::window {
namespace {

using Clock = std::chrono::steady_clock;
using Kind = ViewerAction::Kind;

// Light slots reserved for lights added in the window (each holds a basis buffer per pixel).
constexpr std::uint32_t kSpareLightSlots = 8;

} // namespace

struct Viewer::FrameRecord {
  std::size_t frame = 0;
  bool restarted = false, preview = false, presented = false;
  std::uint64_t retraced = 0;
  double editCpuMs = 0.0;      // host CPU time of this frame's edits (EditReport::cpuMs)
  std::uint64_t rays = 0;      // traced this frame: edits, samples
  double gpuMs = 0.0;          // the renderer's GPU time this frame (its passes' timestamps)
  double renderMs = 0.0;       // wall time of the edits, the samples and the compose
  double denoiseMs = 0.0;      // the denoiser's GPU time (0 when it did not run)
  std::map<std::string, double> passMs; // the renderer's GPU ms per pass this frame
  double presentMs = 0.0;      // wall time of the panel and the presentation (and screenshots)
  double wallMs = 0.0;         // the whole frame on the host's clock, from its input poll to its
                               // end: edits, samples, waits for the device, read-backs, presentation
  std::vector<std::string> actions;
};

Viewer::Viewer(std::unique_ptr<FrameTarget> target, const gpu::ContextOptions& device, scene::Scene scene,
               bvh::Bvh bvh, ViewerConfig config)
    : config_(std::move(config)),
      target_(std::move(target)),
      context_(target_->contextOptions(device)),
      camera_(config_.obscurance.camera, scene.bounds) {
  target_->attach(context_, config_.obscurance.width, config_.obscurance.height, config_.panel);
  if (!config_.log.empty()) {
    log_.open(config_.log);
    if (!log_) throw InputError(fmt::format("{}: cannot write the frame log", config_.log));
  }
  const scene::Bounds& b = scene.bounds;
  sceneSize_ = std::max(glm::length(b.hi - b.lo), 1e-3f);

  // As many samples' rays kept as fit: added lights and moves follow them.
  render::ObscuranceSettings settings = session::editSettings(config_.obscurance, kSpareLightSlots);
  settings.primaryAovs = true; // picking reads the primitive AOV; the AOV list shows them
  settings.composedAovs = true;
  config_.obscurance = settings;
  // On lavapipe the edits' kernels wait for the first edit that needs them: compiling them up front
  // took most of a window's start there (~1.8 s of 3.2 s for a small scene), and a window on the
  // CPU is not a real-time one; on a GPU a first edit must not stall the frame loop.
  const auto editKernels =
      context_.info().type == "cpu" ? session::EditKernels::OnFirstUse : session::EditKernels::UpFront;
  session_ = std::make_unique<session::EditSession>(context_, std::move(scene), std::move(bvh), settings,
                                                    bvh::BuildOptions{}, editKernels);
  session_->renderer().configure(fullSettings());
  denoiser_ = std::make_unique<render::Denoiser>(context_, session_->renderer());
  lastFrameStart_ = Clock::now();
}

Viewer::~Viewer() {
  context_.device().waitIdle();
  target_->detach();
}

render::ObscuranceSettings Viewer::fullSettings() const {
  render::ObscuranceSettings s = config_.obscurance;
  s.camera = camera_.camera();
  return s;
}

void Viewer::restart(bool preview, bool cameraOnly) {
  // A camera move keeps the denoiser's history (it is reprojected); anything else changed the
  // image itself.
  if (!cameraOnly) forgetHistory_ = true;
  render::ObscuranceSettings s = fullSettings();
  if (preview) {
    s.shadowRays = std::min(s.shadowRays, 1u);
    s.obscuranceRays = std::min(s.obscuranceRays, 1u);
    // The emitter edges' probes (four camera rays a pixel) would cost more than the preview's own
    // rays; the frame after it, which starts the accumulation, traces them.
    s.emissionSamples = 1;
  }
  session_->renderer().configure(s);
  pathTracer_.reset(); // made again with the new camera when shown
  previewShown_ = preview;
  needsCompose_ = true;
}

void Viewer::applyEdit(session::Edit edit, FrameRecord& record) {
  using EditKind = session::Edit::Kind;
  if (edit.kind == EditKind::Move && edit.name.empty()) {
    if (selected_ < 0) throw InputError("move: no object is selected");
    edit.name = session_->scene().objects[static_cast<std::size_t>(selected_)].name;
  }
  if (edit.kind == EditKind::Insert) throw InputError("insert: not in the window (relight --edits inserts objects)");
  const session::EditReport report = session_->apply(edit, edit.kindName());
  record.editCpuMs += report.cpuMs;
  forgetHistory_ = true; // the image itself changed
  needsCompose_ = true;
  if (edit.changesGeometry()) {
    pathTracer_.reset(); // it points at the scene before the edit; made again when shown
    record.retraced = report.pixelsRetraced;
  }
  const char* action = "";
  switch (edit.kind) {
  case EditKind::Scale: action = "light_scale"; break;
  case EditKind::Color: action = "light_color"; break;
  case EditKind::AddLight:
  case EditKind::AddQuad:
    action = "add_light";
    status_ = fmt::format("added {}: its rays alone were traced", edit.name);
    break;
  case EditKind::RemoveLight: action = "remove_light"; break;
  case EditKind::MoveLight: action = "move_light"; break;
  case EditKind::Move:
    action = "move_object";
    status_ = fmt::format("moved {}: {} pixels retraced ({:.1f} %)", edit.name, report.pixelsRetraced,
                          100.0 * double(report.pixelsRetraced) /
                              (double(config_.obscurance.width) * config_.obscurance.height));
    break;
  case EditKind::Remove: action = "remove_object"; break;
  case EditKind::Insert: break;
  }
  record.actions.push_back(action);
}

void Viewer::apply(const ViewerAction& a, FrameRecord& record) {
  // A change that restarts the accumulation (`cameraOnly`: the view alone, so the denoiser's
  // history is reprojected rather than forgotten).
  auto restartFor = [&](const char* action, bool cameraOnly) {
    restart(false, cameraOnly);
    record.restarted = true;
    record.actions.push_back(action);
  };
  switch (a.kind) {
  case Kind::Edit:
    applyEdit(a.edit, record);
    break;
  case Kind::SelectObject:
    selected_ = a.name.empty() ? -1 : static_cast<int>(scene::objectIndex(session_->scene(), a.name, "select"));
    record.actions.push_back("select");
    break;
  case Kind::Exposure:
    config_.exposure = a.value;
    needsCompose_ = true;
    record.actions.push_back("exposure");
    break;
  case Kind::Aov: {
    const auto& names = render::obscuranceAovNames();
    if (a.name != "combined" && std::find(names.begin(), names.end(), a.name) == names.end())
      throw InputError(fmt::format("no AOV named '{}' (AOVs: combined, {})", a.name, fmt::join(names, ", ")));
    config_.aov = a.name;
    needsCompose_ = true;
    record.actions.push_back("aov");
    break;
  }
  case Kind::Method:
    config_.method = a.method;
    needsCompose_ = true;
    record.actions.push_back("method");
    break;
  case Kind::Rho:
    config_.obscurance.rho = a.rho;
    restartFor("rho", false);
    break;
  case Kind::DMax:
    config_.obscurance.dMax = a.value;
    restartFor("dmax", false);
    break;
  case Kind::ShadowRays:
    config_.obscurance.shadowRays = static_cast<std::uint32_t>(a.count);
    restartFor("shadow_rays", false);
    break;
  case Kind::ObscuranceRays:
    config_.obscurance.obscuranceRays = static_cast<std::uint32_t>(a.count);
    restartFor("obscurance_rays", false);
    break;
  case Kind::Camera: {
    const auto& cameras = session_->scene().cameras;
    if (a.count >= cameras.size())
      throw InputError(fmt::format("camera {}: the scene has {} camera(s)", a.count, cameras.size()));
    camera_.setCamera(cameras[a.count]);
    restartFor("camera", true);
    break;
  }
  case Kind::Denoise:
    config_.denoise = a.count != 0;
    needsCompose_ = true;
    record.actions.push_back("denoise");
    break;
  case Kind::SaveView:
    saveView(a.name, camera_.camera());
    status_ = fmt::format("view saved to {}", a.name);
    record.actions.push_back("save_view");
    break;
  case Kind::LoadView:
    camera_.setCamera(loadView(a.name));
    restartFor("load_view", true);
    status_ = fmt::format("view loaded from {}", a.name);
    break;
  }
}

int Viewer::pick(double x, double y) {
  const auto drawable = target_->drawableSize();
  if (drawable[0] <= 0 || drawable[1] <= 0) return -1;
  const auto rect = fitToDrawable(config_.obscurance.width, config_.obscurance.height,
                                  {static_cast<std::uint32_t>(drawable[0]), static_cast<std::uint32_t>(drawable[1])});
  const double u = (x - rect[0].x) / double(rect[1].x - rect[0].x), v = (y - rect[0].y) / double(rect[1].y - rect[0].y);
  if (u < 0.0 || u >= 1.0 || v < 0.0 || v >= 1.0) return -1;
  const int px = static_cast<int>(u * config_.obscurance.width), py = static_cast<int>(v * config_.obscurance.height);
  shownBytes(); // compose() writes the display bytes too: keep the frame shown as the light mix made it
  session_->renderer().compose(config_.exposure);
  const io::Image image = session_->renderer().image();
  const int channel = image.channelIndex(render::aovChannels("primitive").front());
  if (channel < 0) return -1;
  const float primitive = image.at(px, py, channel);
  if (!(primitive >= 0.0f)) return -1; // background
  const auto triangle = static_cast<std::uint32_t>(std::lround(primitive));
  const auto& objects = session_->scene().objects;
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (triangle >= objects[i].firstTriangle && triangle < objects[i].firstTriangle + objects[i].triangleCount)
      return static_cast<int>(i);
  return -1;
}

void Viewer::renderStep(FrameRecord& record) {
  const std::uint32_t maxSamples = std::max(config_.obscurance.spp, 1u);
  if (config_.method == render::Method::PathTrace) {
    if (!pathTracer_) {
      render::PathTraceSettings s;
      s.width = config_.obscurance.width;
      s.height = config_.obscurance.height;
      s.seed = config_.obscurance.seed;
      s.camera = camera_.camera();
      s.maxDepth = config_.pathDepth;
      s.spp = maxSamples;
      s.lightSampling = config_.obscurance.lightSampling;
      pathTracer_ = std::make_unique<render::PathTracer>(context_, session_->scene(), session_->bvh(), s,
                                                         config_.obscurance.maxBufferBytes);
      record.restarted = true;
    }
    if (pathTracer_->samples() < maxSamples) {
      pathTracer_->iterate(1);
      needsCompose_ = true;
    }
    if (needsCompose_) {
      shown_ = io::encodeRgba8(pathTracer_->image(), 0, config_.exposure, 3);
      shownAt_ = ShownAt::Host;
    }
    needsCompose_ = false;
    return;
  }

  if (previewShown_ && !record.preview) {
    restart(false, true); // the preview is over: full rays from sample 0, the same view
    record.restarted = true;
  }
  if (session_->renderer().samples() < maxSamples) {
    session_->renderer().iterate(1);
    needsCompose_ = true;
  }

  if (!needsCompose_) return;
  needsCompose_ = false;
  if (config_.aov == "combined" && config_.denoise) {
    if (forgetHistory_) denoiser_->reset();
    forgetHistory_ = false;
    session_->renderer().compose(config_.exposure);
    denoiser_->denoise(session_->renderer(), config_.exposure);
    record.denoiseMs = denoiser_->lastGpuMs();
    shownAt_ = ShownAt::Denoiser;
  } else if (config_.aov == "combined") {
    session_->renderer().composeDisplay(config_.exposure);
    shownAt_ = ShownAt::Renderer;
  } else {
    session_->renderer().compose(config_.exposure);
    const io::Image image = session_->renderer().image();
    const auto channels = render::aovChannels(config_.aov);
    shown_ = io::encodeRgba8(image, image.channelIndex(channels.front()), config_.exposure,
                             static_cast<int>(channels.size()));
    shownAt_ = ShownAt::Host;
  }
}

const std::vector<std::uint32_t>& Viewer::shownBytes() {
  if (shownAt_ == ShownAt::Denoiser) shown_ = denoiser_->display();
  else if (shownAt_ == ShownAt::Renderer) shown_ = session_->renderer().display();
  shownAt_ = ShownAt::Host; // until the next compose
  return shown_;
}

render::RenderStats Viewer::currentStats() const {
  if (config_.method == render::Method::PathTrace) return pathTracer_ ? pathTracer_->stats() : render::RenderStats{};
  return session_->renderer().stats();
}

PanelState Viewer::panelState() const {
  PanelState s;
  s.method = config_.method;
  s.aov = config_.aov;
  s.aovs = {"combined"};
  for (const auto& name : render::obscuranceAovNames())
    if (name != "combined") s.aovs.push_back(name);
  s.rho = config_.obscurance.rho;
  s.exposure = config_.exposure;
  s.dMax = session_->renderer().dMax();
  s.shadowRays = config_.obscurance.shadowRays;
  s.obscuranceRays = config_.obscurance.obscuranceRays;
  s.denoise = config_.denoise;
  s.samples = config_.method == render::Method::PathTrace && pathTracer_ ? pathTracer_->samples() : session_->renderer().samples();
  s.maxSamples = std::max(config_.obscurance.spp, 1u);
  s.preview = previewShown_;
  s.frameMs = lastFrameMs_;
  const auto stats = currentStats();
  s.passes = stats.passes;
  if (config_.denoise && config_.method == render::Method::Obscurance) s.passes["denoise (last frame)"] = {denoiser_->lastGpuMs(), 0};
  const double ms = stats.totalGpuMs();
  s.raysPerSecond = ms > 0 ? double(stats.totalRays()) / (ms * 1e-3) : 0.0;
  for (const auto& l : session_->lights())
    s.lights.push_back({l.name, l.scale, l.color, l.added && !l.area, l.light.position});
  for (const auto& c : session_->scene().cameras) s.cameras.push_back(c.name);
  if (selected_ >= 0) s.selected = session_->scene().objects[static_cast<std::size_t>(selected_)].name;
  const scene::Camera& cam = camera_.camera();
  s.newLightPosition = cam.position + cam.forward * (0.15f * sceneSize_);
  s.newLightIntensity = 0.05f * sceneSize_ * sceneSize_;
  s.sceneSize = sceneSize_;
  s.status = status_;
  s.viewFile = config_.viewFile;
  return s;
}

void Viewer::writeLog(const FrameRecord& r) {
  if (!log_) return;
  nlohmann::json line = {{"frame", r.frame},
                         {"method", nameString(render::kMethodNames, config_.method)},
                         {"samples", config_.method == render::Method::PathTrace && pathTracer_ ? pathTracer_->samples()
                                                                                   : session_->renderer().samples()},
                         {"restarted", r.restarted},
                         {"preview", r.preview},
                         {"presented", r.presented},
                         {"pixels_retraced", r.retraced},
                         {"edit_cpu_ms", r.editCpuMs},
                         {"rays", r.rays},
                         {"gpu_ms", r.gpuMs},
                         {"render_ms", r.renderMs},
                         {"denoise_ms", r.denoiseMs},
                         {"pass_ms", r.passMs},
                         {"present_ms", r.presentMs},
                         {"frame_gpu_ms", r.gpuMs + r.denoiseMs},
                         {"wall_ms", r.wallMs},
                         {"frame_ms", r.wallMs}, // wall_ms's older name (tools/bench_view.sh)
                         {"actions", r.actions}};
  log_ << line.dump() << "\n";
  log_.flush();
}

io::Image Viewer::shownImage() {
  if (config_.method == render::Method::PathTrace) return pathTracer_->image();
  if (config_.aov == "combined" && config_.denoise) return denoiser_->image();
  shownBytes(); // as in pick(): compose() overwrites the display bytes not yet read back
  session_->renderer().compose(config_.exposure);
  return session_->renderer().image();
}

void Viewer::takeScreenshot(const std::string& path, const std::vector<std::uint32_t>& captured,
                            vk::Extent2D extent) {
  if (io::extensionOf(path) == "exr") {
    io::writeExr(path, shownImage()); // linear, every AOV the frame keeps
    return;
  }
  if (config_.screenshotUi) {
    if (captured.empty()) throw DeviceError(fmt::format("{}: no frame was presented to capture (minimised?)", path));
    io::writePngRgba8(path, static_cast<int>(extent.width), static_cast<int>(extent.height), captured);
  } else {
    io::writePngRgba8(path, static_cast<int>(config_.obscurance.width), static_cast<int>(config_.obscurance.height),
                      shownBytes());
  }
}

void Viewer::run() {
  bool panelVisible = config_.panel;
  for (frame_ = 0; config_.frames == 0 || frame_ < config_.frames; ++frame_) {
    const auto start = Clock::now();
    // The fly step: the frame's time, but at most 0.1 s, so that one slow frame (seconds on
    // lavapipe) does not throw the camera through a wall; a script steps 1/30 s per frame, so its
    // keys move the camera the same on every machine.
    const double seconds = config_.script.empty()
                               ? std::min(std::chrono::duration<double>(start - lastFrameStart_).count(), 0.1)
                               : 1.0 / 30.0;
    lastFrameStart_ = start;
    FrameRecord record;
    record.frame = frame_;

    InputState& input = target_->input();
    input.beginFrame();
    const auto drawable = target_->drawableSize();
    // A person's window waits for input while there is nothing to do (minimised, or every sample
    // done and nothing changed last frame) instead of spinning; a script never waits.
    const bool idle = drawable[0] == 0 || idleLastFrame_;
    target_->pollEvents(idle && config_.script.empty() ? 0.05 : 0.0);
    if (target_->shouldClose()) break;
    config_.script.feed(frame_, input);
    std::vector<ViewerAction> actions;
    UiOverlay* overlay = panelVisible ? target_->overlay() : nullptr;
    if (overlay) {
      overlay->beginFrame(input);
      actions = drawControlPanel(panelState());
    }
    std::vector<std::string> screenshots;
    for (const ScriptEvent* e : config_.script.eventsAt(frame_)) {
      if (e->kind == ScriptEvent::Kind::Panel) actions.push_back(e->action);
      else if (e->kind == ScriptEvent::Kind::Window) target_->applyWindowEvent(*e);
      else screenshots.push_back(e->text);
    }
    if (!input.uiWantsKeyboard) {
      for (int key : input.keysPressed) {
        if (key == GLFW_KEY_ESCAPE) target_->requestClose();
        if (key == GLFW_KEY_TAB) panelVisible = !panelVisible;
        if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9 && std::size_t(key - GLFW_KEY_1) < session_->scene().cameras.size()) {
          ViewerAction a;
          a.kind = Kind::Camera;
          a.count = static_cast<std::size_t>(key - GLFW_KEY_1);
          actions.push_back(a);
        }
        if (key == GLFW_KEY_F5 || key == GLFW_KEY_F9) {
          ViewerAction a;
          a.kind = key == GLFW_KEY_F5 ? Kind::SaveView : Kind::LoadView;
          a.name = config_.viewFile;
          actions.push_back(a);
        }
      }
    }
    if (!input.uiWantsMouse)
      for (const auto& click : input.clicks) {
        const int object = pick(click[0], click[1]);
        selected_ = object;
        status_ = object >= 0 ? fmt::format("selected {}", session_->scene().objects[std::size_t(object)].name)
                              : "nothing selected";
        record.actions.push_back("pick");
      }

    const auto renderStart = Clock::now();
    const render::RenderStats before = currentStats();
    for (const auto& a : actions) {
      try {
        apply(a, record);
      } catch (const InputError& e) {
        // A person's mistake on the panel is shown there; a script's is fatal (tests must see it).
        if (!config_.script.empty()) throw;
        status_ = e.what();
      }
    }
    if (camera_.update(input, seconds)) {
      restart(true, true);
      record.preview = true;
      record.restarted = true;
      record.actions.push_back("camera_move"); // a drag, a key, the wheel (the log tells them apart from edits)
    }
    renderStep(record);
    const render::RenderStats after = currentStats();
    // A restart zeroes the renderer's counters: then all it counts is this frame's.
    record.rays = after.totalRays() - (record.restarted ? 0 : before.totalRays());
    record.gpuMs = after.totalGpuMs() - (record.restarted ? 0.0 : before.totalGpuMs());
    for (const auto& [name, pass] : after.passes) {
      const auto was = before.passes.find(name);
      const double ms = pass.gpuMs - (record.restarted || was == before.passes.end() ? 0.0 : was->second.gpuMs);
      if (ms > 0.0) record.passMs[name] = ms;
    }
    const auto presentStart = Clock::now();
    record.renderMs = std::chrono::duration<double, std::milli>(presentStart - renderStart).count();

    std::vector<std::uint32_t> captured;
    vk::Extent2D capturedExtent{};
    const bool lastFrame = config_.frames != 0 && frame_ + 1 == config_.frames;
    const bool capture = config_.screenshotUi && (!screenshots.empty() || (lastFrame && !config_.screenshot.empty()));
    if (target_->presents())
      record.presented = target_->present(shownBytes(), overlay, capture ? &captured : nullptr, &capturedExtent);
    if (overlay && !record.presented) overlay->discardFrame();
    for (const auto& path : screenshots) takeScreenshot(path, captured, capturedExtent);
    if (lastFrame && !config_.screenshot.empty()) takeScreenshot(config_.screenshot, captured, capturedExtent);
    record.presentMs = std::chrono::duration<double, std::milli>(Clock::now() - presentStart).count();
    record.wallMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    lastFrameMs_ = record.wallMs;
    writeLog(record);
    idleLastFrame_ = record.rays == 0 && record.actions.empty() && !record.restarted && !needsCompose_;
  }
  context_.device().waitIdle();
}

} // namespace obscura::window
