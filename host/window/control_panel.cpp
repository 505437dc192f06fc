// control_panel.cpp — see control_panel.h.
#include "window/control_panel.h"

#include <cmath>

#include <fmt/format.h>
#include <imgui.h>

namespace obscura::window {
namespace {

using Kind = ViewerAction::Kind;
using session::Edit;

ViewerAction action(Kind kind) {
  ViewerAction a;
  a.kind = kind;
  return a;
}

// A change to the scene, applied by the viewer's edit session.
ViewerAction edit(const Edit& e) {
  ViewerAction a;
  a.kind = Kind::Edit;
  a.edit = e;
  a.name = e.name;
  return a;
}

bool combo(const char* label, const std::string& current, const std::vector<std::string>& items, std::string& chosen) {
  bool changed = false;
  if (ImGui::BeginCombo(label, current.c_str())) {
    for (const auto& item : items) {
      if (ImGui::Selectable(item.c_str(), item == current) && item != current) {
        chosen = item;
        changed = true;
      }
    }
    ImGui::EndCombo();
  }
  return changed;
}

// A combo over an enum's names (core/names.h): the panel offers the words the command line takes.
template <typename E, std::size_t N>
bool namedCombo(const char* label, E current, const NameTable<E, N>& table, E& chosen) {
  std::string picked;
  if (!combo(label, nameString(table, current), namesOf(table), picked)) return false;
  chosen = *valueNamed(table, picked);
  return true;
}

} // namespace

const char* viewerControlsHelp() {
  return "left drag: orbit | right drag: pan | middle drag, wheel: dolly | W A S D Q E: fly (Shift: faster)\n"
         "click: select an object | 1-9: glTF cameras | F5: save view | F9: load view | Tab: panel | Esc: quit";
}

std::vector<ViewerAction> drawControlPanel(const PanelState& s) {
  std::vector<ViewerAction> out;
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(300, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("obscura");

  ImGui::Text("%.1f ms/frame (%.0f fps)  %.2f Mrays/s", s.frameMs, s.frameMs > 0 ? 1000.0 / s.frameMs : 0.0,
              s.raysPerSecond / 1e6);
  ImGui::Text("samples %u / %u%s", s.samples, s.maxSamples, s.preview ? "  (preview)" : "");
  if (ImGui::CollapsingHeader("GPU ms per pass (since restart)")) {
    for (const auto& [name, pass] : s.passes)
      ImGui::Text("%-12s %8.1f ms  %6.2f Mrays/s", name.c_str(), pass.gpuMs,
                  pass.gpuMs > 0 ? double(pass.rays) / (pass.gpuMs * 1e3) : 0.0);
  }
  if (!s.status.empty()) ImGui::TextWrapped("%s", s.status.c_str());

  std::string chosen;
  if (auto a = action(Kind::Method); namedCombo("method", s.method, render::kMethodNames, a.method)) out.push_back(a);
  if (combo("AOV", s.aov, s.aovs, chosen)) {
    auto a = action(Kind::Aov);
    a.name = chosen;
    out.push_back(a);
  }
  float exposure = s.exposure;
  if (ImGui::SliderFloat("exposure", &exposure, -8.0f, 8.0f, "%.1f stops")) {
    auto a = action(Kind::Exposure);
    a.value = exposure;
    out.push_back(a);
  }
  bool denoise = s.denoise;
  if (ImGui::Checkbox("denoise", &denoise)) {
    auto a = action(Kind::Denoise);
    a.count = denoise ? 1 : 0;
    out.push_back(a);
  }

  if (ImGui::CollapsingHeader("obscurances")) {
    if (auto a = action(Kind::Rho); namedCombo("rho", s.rho, render::kRhoKindNames, a.rho)) out.push_back(a);
    float dMax = s.dMax;
    if (ImGui::SliderFloat("dmax", &dMax, 0.001f * s.sceneSize, s.sceneSize, "%.3f m", ImGuiSliderFlags_Logarithmic)) {
      auto a = action(Kind::DMax);
      a.value = dMax;
      out.push_back(a);
    }
    int shadow = static_cast<int>(s.shadowRays), obscurance = static_cast<int>(s.obscuranceRays);
    if (ImGui::SliderInt("shadow rays", &shadow, 0, 64)) {
      auto a = action(Kind::ShadowRays);
      a.count = static_cast<std::size_t>(shadow);
      out.push_back(a);
    }
    if (ImGui::SliderInt("obscurance rays", &obscurance, 0, 64)) {
      auto a = action(Kind::ObscuranceRays);
      a.count = static_cast<std::size_t>(obscurance);
      out.push_back(a);
    }
  }

  if (ImGui::CollapsingHeader("lights", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (s.method == render::Method::PathTrace) ImGui::TextWrapped("path tracing shows the scene's own lights; edits here are the obscurance method's");
    for (const auto& light : s.lights) {
      ImGui::PushID(light.name.c_str());
      ImGui::TextUnformatted(light.name.c_str());
      float scale = light.scale;
      if (ImGui::SliderFloat("intensity", &scale, 0.0f, 16.0f, "x %.2f", ImGuiSliderFlags_Logarithmic)) {
        out.push_back(edit({.kind = Edit::Kind::Scale, .name = light.name, .scale = scale}));
      }
      float color[3] = {light.color.x, light.color.y, light.color.z};
      if (ImGui::ColorEdit3("colour", color, ImGuiColorEditFlags_Float | ImGuiColorEditFlags_HDR)) {
        out.push_back(edit({.kind = Edit::Kind::Color, .name = light.name, .color = {color[0], color[1], color[2]}}));
      }
      if (light.added) {
        float p[3] = {light.position.x, light.position.y, light.position.z};
        if (ImGui::DragFloat3("position", p, 0.005f * s.sceneSize)) {
          out.push_back(edit({.kind = Edit::Kind::MoveLight, .name = light.name, .position = {p[0], p[1], p[2]}}));
        }
        if (ImGui::Button("remove")) {
          out.push_back(edit({.kind = Edit::Kind::RemoveLight, .name = light.name}));
        }
      }
      ImGui::PopID();
    }
    if (ImGui::Button("add point light in front of the camera")) {
      Edit add{.kind = Edit::Kind::AddLight, .name = fmt::format("point{}", s.lights.size())};
      add.light.type = scene::PunctualType::Point;
      add.light.position = s.newLightPosition;
      add.light.intensity = s.newLightIntensity;
      add.light.name = add.name;
      out.push_back(edit(add));
    }
  }

  if (ImGui::CollapsingHeader("object", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (s.selected.empty()) {
      ImGui::TextUnformatted("click an object to select it");
    } else {
      ImGui::Text("selected: %s", s.selected.c_str());
      static float offset[3] = {0.0f, 0.0f, 0.0f};
      ImGui::DragFloat3("offset", offset, 0.002f * s.sceneSize);
      if (ImGui::Button("move by offset")) {
        // No name: the selected object.
        out.push_back(edit({.kind = Edit::Kind::Move, .translate = {offset[0], offset[1], offset[2]}}));
      }
      ImGui::SameLine();
      if (ImGui::Button("deselect")) out.push_back(action(Kind::SelectObject));
    }
  }

  if (ImGui::CollapsingHeader("camera")) {
    for (std::size_t i = 0; i < s.cameras.size(); ++i) {
      if (ImGui::Button(fmt::format("{}: {}", i + 1, s.cameras[i]).c_str())) {
        auto a = action(Kind::Camera);
        a.count = i;
        out.push_back(a);
      }
    }
    if (ImGui::Button("save view")) {
      auto a = action(Kind::SaveView);
      a.name = s.viewFile;
      out.push_back(a);
    }
    ImGui::SameLine();
    if (ImGui::Button("load view")) {
      auto a = action(Kind::LoadView);
      a.name = s.viewFile;
      out.push_back(a);
    }
  }
  ImGui::Separator();
  ImGui::TextWrapped("%s", viewerControlsHelp());
  ImGui::End();
  return out;
}

} // namespace obscura::window
