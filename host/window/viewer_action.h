// viewer_action.h — one change a person asks of the viewer, from the panel or a script: both go
// through Viewer::apply, so a scripted run exercises exactly what a click does.
#pragma once
#include <cstddef>
#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace obscura::window {

struct ViewerAction {
  enum class Kind {
    LightScale,    // light `name`: intensity multiplier `value` (compose only)
    LightColor,    // light `name`: RGB multipliers `vector` (compose only)
    AddLight,      // `light` (point or spot): traces that light alone
    RemoveLight,   // light `name`
    MoveLight,     // added light `name` to `vector` (dragged): its rays alone, traced again
    SelectObject,  // object `name` ("" = none)
    MoveObject,    // object `name` (or the selected one when empty) by `vector`: dirty pixels only
    Exposure,      // `value` stops (display only)
    Aov,           // show AOV `name`
    Method,        // "obscurance" or "pathtrace"
    Rho,           // "sqrt", "exp" or "ao" (restarts)
    DMax,          // `value` metres (restarts)
    ShadowRays,    // `count` (restarts)
    ObscuranceRays,// `count` (restarts)
    Camera,        // glTF camera `count`
    Denoise,       // `count` != 0: on
    SaveView,      // to file `name`
    LoadView,      // from file `name`
  };
  Kind kind = Kind::Exposure;
  std::string name;
  float value = 0.0f;
  glm::vec3 vector{0.0f};
  std::size_t count = 0;
  scene::PunctualLight light;
};

} // namespace obscura::window
