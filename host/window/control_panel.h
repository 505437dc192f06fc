// control_panel.h — the viewer's Dear ImGui panel: what is rendered and how fast, and the controls
// that edit it. It only reads a PanelState and returns ViewerActions; the viewer applies them, as it
// applies a script's.
#pragma once
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/aovs.h"
#include "render/method.h"
#include "render/obscurance_renderer.h"
#include "window/viewer_action.h"

namespace obscura::window {

struct PanelState {
  render::Method method = render::Method::Obscurance;
  render::RhoKind rho = render::RhoKind::Sqrt;
  std::string aov;
  std::vector<std::string> aovs;       // what the AOV list offers
  float exposure = 0.0f, dMax = 0.0f;
  std::uint32_t shadowRays = 0, obscuranceRays = 0;
  bool denoise = false;
  std::uint32_t samples = 0, maxSamples = 0;
  bool preview = false;
  double frameMs = 0.0, raysPerSecond = 0.0;
  std::map<std::string, render::PassStats> passes; // GPU ms and rays since the last restart
  struct Light {
    std::string name;
    float scale = 1.0f;
    glm::vec3 color{1.0f};
    bool added = false;
    glm::vec3 position{0.0f};
  };
  std::vector<Light> lights;
  std::vector<std::string> cameras;
  std::string selected;                // "" = no object selected
  glm::vec3 newLightPosition{0.0f};    // where "Add point light" puts one (in front of the camera)
  float newLightIntensity = 1.0f;
  float sceneSize = 1.0f;
  std::string status;                  // the last edit's outcome
  std::string viewFile;
};

// Draws the panel; returns what the person changed this frame.
std::vector<ViewerAction> drawControlPanel(const PanelState& state);

// The key and mouse bindings, as `view --help` and the panel list them.
const char* viewerControlsHelp();

} // namespace obscura::window
