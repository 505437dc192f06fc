// progress.h — a Python progress callback as the renderers' ProgressFn: called with the GIL taken
// (the render runs without it), `done, total, seconds`; an exception it raises ends the render.
#pragma once
#include <pybind11/pybind11.h>

#include "render/aovs.h"

namespace obscura::python {

// None gives no callback. `callback` must outlive the render.
inline render::ProgressFn progressCallback(const pybind11::object& callback) {
  if (callback.is_none()) return {};
  return [&callback](std::uint32_t done, std::uint32_t total, double seconds) {
    pybind11::gil_scoped_acquire acquire;
    callback(done, total, seconds);
  };
}

} // namespace obscura::python
