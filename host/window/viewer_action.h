// viewer_action.h — one change a person asks of the viewer, from the panel or a script: both go
// through Viewer::apply, so a scripted run exercises exactly what a click does. A change to the
// scene (a light, an object) is an Edit, the same as `relight --edits` applies, through the same
// EditSession (session/edit_session.h); the others change what the window shows or samples.
#pragma once
#include <cstddef>
#include <string>

#include <glm/glm.hpp>

#include "render/method.h"
#include "render/obscurance_renderer.h"
#include "session/edit.h"

namespace obscura::window {

struct ViewerAction {
  enum class Kind {
    Edit,          // `edit` (session/edit.h); a Move naming no object moves the selected one
    SelectObject,  // object `name` ("" = none)
    Exposure,      // `value` stops (display only)
    Aov,           // show AOV `name`
    Method,        // `method`
    Rho,           // `rho` (restarts)
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
  std::size_t count = 0;
  render::Method method = render::Method::Obscurance;
  render::RhoKind rho = render::RhoKind::Sqrt;
  session::Edit edit;
};

} // namespace obscura::window
