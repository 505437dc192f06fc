// event_script.cpp — see event_script.h.
#include "window/event_script.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"
#include "io/json_fields.h"
#include "io/json_file.h"
#include "relight/light_edits.h"

namespace obscura::window {
namespace {

using nlohmann::json;

// GLFW's code of a key named as on the keyboard: a letter or digit, "Space", "Escape", "F1".."F12".
int keyCode(std::string name, const io::JsonEntry& at) {
  if (name.size() == 1) {
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(name[0])));
    if (c >= 'A' && c <= 'Z') return GLFW_KEY_A + (c - 'A');
    if (c >= '0' && c <= '9') return GLFW_KEY_0 + (c - '0');
  }
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  if (name == "space") return GLFW_KEY_SPACE;
  if (name == "escape") return GLFW_KEY_ESCAPE;
  if (name == "shift") return GLFW_KEY_LEFT_SHIFT;
  if (name.size() >= 2 && name[0] == 'f') {
    try {
      const int n = std::stoi(name.substr(1));
      if (n >= 1 && n <= 12) return GLFW_KEY_F1 + n - 1;
    } catch (const std::exception&) {
    }
  }
  at.fail(fmt::format("unknown key '{}' (letters, digits, Space, Escape, Shift, F1-F12)", name));
}

std::size_t count(const json& j, const char* key, const io::JsonEntry& at, std::size_t max) {
  const float v = io::jsonNumber(j, key, at);
  if (v < 0.0f || v > static_cast<float>(max) || v != std::floor(v))
    at.fail(fmt::format("'{}' must be a whole number from 0 to {}", key, max));
  return static_cast<std::size_t>(v);
}

std::array<double, 2> pair(const json& j, const char* key, const io::JsonEntry& at) {
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
    at.fail(fmt::format("'{}' must be an array of 2 numbers", key));
  return {v[0].get<double>(), v[1].get<double>()};
}

ViewerAction panelAction(const json& p, const io::JsonEntry& at) {
  using Kind = ViewerAction::Kind;
  if (!p.is_object() || p.empty()) at.fail("'panel' must be an object naming one change");
  ViewerAction a;
  if (p.contains("light") || p.contains("add_light") || p.contains("remove_light") || p.contains("move_light") ||
      p.contains("move") || p.contains("remove")) {
    // A scene edit, in the words of `relight --edits` (relight/light_edits.h).
    a.kind = Kind::Edit;
    a.edit = relight::readEdit(p, at);
    a.name = a.edit.name;
  } else if (p.contains("select")) {
    a.kind = Kind::SelectObject;
    if (!p.at("select").is_string()) at.fail("'select' must be an object's name");
    a.name = p.at("select").get<std::string>();
  } else if (p.contains("exposure")) {
    a.kind = Kind::Exposure;
    a.value = io::jsonNumber(p, "exposure", at);
  } else if (p.contains("aov")) {
    a.kind = Kind::Aov;
    a.name = io::jsonText(p, "aov", at);
  } else if (p.contains("method")) {
    a.kind = Kind::Method;
    a.method = io::jsonNamed(p, "method", render::kMethodNames, at);
  } else if (p.contains("rho")) {
    a.kind = Kind::Rho;
    a.rho = io::jsonNamed(p, "rho", render::kRhoKindNames, at);
  } else if (p.contains("dmax")) {
    a.kind = Kind::DMax;
    a.value = io::jsonNumber(p, "dmax", at);
    if (!(a.value > 0.0f)) at.fail("'dmax' must be positive");
  } else if (p.contains("shadow_rays")) {
    a.kind = Kind::ShadowRays;
    a.count = count(p, "shadow_rays", at, 256);
  } else if (p.contains("obscurance_rays")) {
    a.kind = Kind::ObscuranceRays;
    a.count = count(p, "obscurance_rays", at, 256);
  } else if (p.contains("camera")) {
    a.kind = Kind::Camera;
    a.count = count(p, "camera", at, 1u << 20);
  } else if (p.contains("denoise")) {
    a.kind = Kind::Denoise;
    if (!p.at("denoise").is_boolean()) at.fail("'denoise' must be true or false");
    a.count = p.at("denoise").get<bool>() ? 1 : 0;
  } else if (p.contains("save_view")) {
    a.kind = Kind::SaveView;
    a.name = io::jsonText(p, "save_view", at);
  } else if (p.contains("load_view")) {
    a.kind = Kind::LoadView;
    a.name = io::jsonText(p, "load_view", at);
  } else {
    at.fail(fmt::format("unknown panel change {}", p.dump()));
  }
  return a;
}

} // namespace

EventScript::EventScript(const std::string& path) {
  const json file = io::readJsonFile(path, "cannot read the script");
  if (!file.is_array()) throw InputError(fmt::format("{}: a script is a JSON list of events", path));
  for (std::size_t i = 0; i < file.size(); ++i) {
    const io::JsonEntry at{path, i};
    const json& e = file[i];
    if (!e.is_object()) at.fail("an event is an object");
    ScriptEvent ev;
    ev.frame = count(e, "frame", at, 1u << 24);
    int kinds = 0;
    if (e.contains("key")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Key;
      ev.key = keyCode(io::jsonText(e, "key", at), at);
      ev.hold = e.contains("hold") ? static_cast<int>(count(e, "hold", at, 1u << 20)) : 1;
    }
    if (e.contains("drag")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Drag;
      ev.xy = pair(e, "drag", at);
      const std::string button = e.contains("button") ? io::jsonText(e, "button", at) : "left";
      if (button == "left") ev.button = 0;
      else if (button == "right") ev.button = 1;
      else if (button == "middle") ev.button = 2;
      else at.fail("'button' is left, right or middle");
    }
    if (e.contains("click")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Click;
      ev.xy = pair(e, "click", at);
    }
    if (e.contains("scroll")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Scroll;
      ev.scroll = io::jsonNumber(e, "scroll", at);
    }
    if (e.contains("panel")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Panel;
      ev.action = panelAction(e.at("panel"), at);
    }
    if (e.contains("window")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Window;
      ev.text = io::jsonText(e, "window", at);
      if (ev.text == "resize") {
        if (!e.contains("size")) at.fail("a resize needs 'size': [width, height]");
        ev.xy = pair(e, "size", at);
        if (!(ev.xy[0] >= 1 && ev.xy[1] >= 1 && ev.xy[0] <= 16384 && ev.xy[1] <= 16384))
          at.fail("'size' must be from 1 to 16384 pixels");
      } else if (ev.text != "minimize" && ev.text != "restore" && ev.text != "close") {
        at.fail("'window' is resize, minimize, restore or close");
      }
    }
    if (e.contains("screenshot")) {
      ++kinds;
      ev.kind = ScriptEvent::Kind::Screenshot;
      ev.text = io::jsonText(e, "screenshot", at);
    }
    if (kinds != 1)
      at.fail("an event has 'frame' and exactly one of key, drag, click, scroll, panel, window, screenshot");
    events_.push_back(std::move(ev));
  }
}

void EventScript::feed(std::size_t frame, InputState& in) const {
  for (const auto& e : events_) {
    switch (e.kind) {
    case ScriptEvent::Kind::Key:
      if (frame >= e.frame && frame < e.frame + static_cast<std::size_t>(e.hold)) in.keyDown[e.key] = true;
      if (frame == e.frame) in.keysPressed.push_back(e.key);
      if (frame == e.frame + static_cast<std::size_t>(e.hold)) in.keyDown[e.key] = false;
      break;
    case ScriptEvent::Kind::Drag:
      if (frame == e.frame) {
        in.buttonDown[e.button] = true;
        in.mouseDx += e.xy[0];
        in.mouseDy += e.xy[1];
      } else if (frame == e.frame + 1) {
        in.buttonDown[e.button] = false;
      }
      break;
    case ScriptEvent::Kind::Click:
      if (frame == e.frame) in.clicks.push_back(e.xy);
      break;
    case ScriptEvent::Kind::Scroll:
      if (frame == e.frame) in.scroll += e.scroll;
      break;
    default:
      break;
    }
  }
}

std::size_t EventScript::length() const {
  std::size_t end = 0;
  for (const auto& e : events_) {
    // A drag releases its button the frame after; a held key is released at frame + hold.
    const std::size_t last = e.kind == ScriptEvent::Kind::Key ? e.frame + std::max<std::size_t>(static_cast<std::size_t>(e.hold), 1) - 1
                                                                   : e.frame;
    end = std::max(end, last + 1);
  }
  return end;
}

std::vector<const ScriptEvent*> EventScript::eventsAt(std::size_t frame) const {
  std::vector<const ScriptEvent*> out;
  for (const auto& e : events_)
    if (e.frame == frame && (e.kind == ScriptEvent::Kind::Panel || e.kind == ScriptEvent::Kind::Window ||
                             e.kind == ScriptEvent::Kind::Screenshot))
      out.push_back(&e);
  return out;
}

} // namespace obscura::window
