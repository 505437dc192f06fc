// viewer.h — `obscura view`: the real-time window. A frame loop around the persistent renderers
// (render/obscurance_renderer.h, render/path_tracer.h) that
//   - renders progressively: one sample per frame, accumulated until something changes (up to
//     `maxSamples`), the first frame after a camera move a cheap preview (one primary sample, one
//     shadow and one obscurance ray);
//   - edits as the relighting paper does: a light's intensity or colour is one compose pass (the
//     accumulation goes on), an added or dragged light traces only that light, a moved object
//     retraces only the pixels it can change, and a camera move restarts;
//   - shows it on a FrameTarget (window/frame_target.h): a window with the panel
//     (window/control_panel.h) over it, driven by a person or a script (WindowTarget), or nowhere,
//     driven by a script alone (OffscreenTarget, `view --offscreen`). The loop, the actions and the
//     log are the same for both.
#pragma once
#include <chrono>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "render/denoise/denoiser.h"
#include "render/obscurance_renderer.h"
#include "render/path_tracer.h"
#include "scene/scene.h"
#include "session/edit_session.h"
#include "window/camera_controller.h"
#include "window/control_panel.h"
#include "window/event_script.h"
#include "window/frame_target.h"
#include "window/viewer_action.h"

namespace obscura::window {

struct ViewerConfig {
  std::string title = "obscura";
  render::ObscuranceSettings obscurance; // size, camera, rays; spp = the samples accumulated
  std::uint32_t pathDepth = 6;
  render::Method method = render::Method::Obscurance;
  std::string aov = "combined";
  float exposure = 0.0f;
  bool denoise = true;                   // the denoiser (render/denoise/) on the combined image
  bool panel = true;
  std::size_t frames = 0;                // frames to show, then exit; 0: until the window closes
  std::string screenshot;                // the last frame, as shown (PNG), or linear (EXR)
  bool screenshotUi = false;             // screenshots include the panel
  EventScript script;                    // replayed input (window/event_script.h); empty: none
  std::string log;                       // one JSON line per frame
  std::string viewFile = "view.json";    // F5 saves the view there, F9 loads it
};

class Viewer {
public:
  // Makes the device (with what `target` needs of it), attaches the target and makes the renderer.
  Viewer(std::unique_ptr<FrameTarget> target, const gpu::ContextOptions& device, scene::Scene scene, bvh::Bvh bvh,
         ViewerConfig config);
  ~Viewer();
  // The frame loop, until the target closes (the window, a script's "close") or `frames` have
  // been shown.
  void run();

private:
  struct FrameRecord; // what one frame did, for the log and the panel
  void apply(const ViewerAction& action, FrameRecord& record);
  // Restarts accumulation with the current settings (and camera); `cameraOnly`: only the view
  // changed (the denoiser's history is then reprojected, not forgotten).
  void restart(bool preview, bool cameraOnly = false);
  void renderStep(FrameRecord& record);
  // The display bytes of the frame last rendered, read back on first use after renderStep: a
  // window reads them every frame, offscreen only a screenshot does.
  const std::vector<std::uint32_t>& shownBytes();
  // The object under window pixel (x, y), from the primitive AOV; -1 for none.
  int pick(double x, double y);
  // A scene edit, through the session; what the window shows follows.
  void applyEdit(session::Edit edit, FrameRecord& record);
  render::ObscuranceSettings fullSettings() const;
  PanelState panelState() const;
  // The shown method's counters since its last restart.
  render::RenderStats currentStats() const;
  void writeLog(const FrameRecord& record);
  // The frame shown, linear (the AOVs of an obscurance frame; combined for path tracing).
  io::Image shownImage();
  void takeScreenshot(const std::string& path, const std::vector<std::uint32_t>& captured,
                      vk::Extent2D capturedExtent);

  ViewerConfig config_;
  std::unique_ptr<FrameTarget> target_; // detached in ~Viewer, before the context goes
  gpu::Context context_;
  std::ofstream log_;

  float sceneSize_ = 1.0f;
  CameraController camera_;
  // The scene as edited so far, its renderer and its lights (session/edit_session.h).
  std::unique_ptr<session::EditSession> session_;
  std::unique_ptr<render::PathTracer> pathTracer_; // made when first shown, again after edits
  // The denoiser of the obscurance frame (on by default): its history follows the camera; any
  // other change forgets it (forgetHistory_).
  std::unique_ptr<render::Denoiser> denoiser_;
  bool forgetHistory_ = true;

  int selected_ = -1;
  bool previewShown_ = false;
  bool needsCompose_ = true;
  bool idleLastFrame_ = false; // nothing traced or changed: the next poll may wait for input
  // Where the shown frame's display bytes are until shownBytes() reads them back: on the device
  // (the renderer's or the denoiser's display buffer), or already in shown_.
  enum class ShownAt { Host, Renderer, Denoiser };
  ShownAt shownAt_ = ShownAt::Host;
  std::vector<std::uint32_t> shown_;
  std::size_t frame_ = 0;
  std::string status_; // the last edit's outcome, shown on the panel
  double lastFrameMs_ = 0.0;
  std::chrono::steady_clock::time_point lastFrameStart_;
};

} // namespace obscura::window
