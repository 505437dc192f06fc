// result.h — obscura.Result: one finished frame on the host. Its AOVs are NumPy views of the frame
// read back once; with the obscurance method it keeps the per-light transport
// (relight/relight_state.h), so that relight() recomposes it with new light scales and colours
// without a ray (render/transport.h composeTransport, the C++ twin of compose.comp: what
// `obscura relight DIR` does).
#pragma once
#include <memory>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include "io/image_io.h"
#include "relight/relight_state.h"

namespace obscura::python {

struct Result {
  std::shared_ptr<const io::Image> aovs;
  std::optional<relight::RelightState> state; // obscurance method only
  int width = 0, height = 0;
  std::vector<std::uint32_t> display;         // tonemapped combined (RGBA8), may be empty
  nlohmann::json stats;                       // figures of the render (statsJson, method, ...)
  // The light layers at the state's emissions, made on first use.
  mutable std::shared_ptr<const io::Image> layers;

  const relight::RelightState& relightState(const char* what) const;
};

// A Result from a state (loaded from a folder, or a session's frame) and the AOVs composed with it.
Result resultOf(relight::RelightState state, std::shared_ptr<const io::Image> aovs, std::vector<std::uint32_t> display,
                nlohmann::json stats);

} // namespace obscura::python
