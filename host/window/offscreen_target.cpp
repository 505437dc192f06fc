// offscreen_target.cpp — see offscreen_target.h.
#include "window/offscreen_target.h"

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::window {

void OffscreenTarget::applyWindowEvent(const ScriptEvent& e) {
  if (e.text == "close") closed_ = true;
  else throw InputError(fmt::format("script: the window event '{}' needs a window (not --offscreen)", e.text));
}

} // namespace obscura::window
