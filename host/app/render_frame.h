// render_frame.h — one finished frame of a scene, in memory: what `obscura render` writes to files
// and what the Python API (python/) returns as arrays. The options are the command line's
// (app/render_options.h), checked here once for both.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/render_options.h"
#include "app/scene_setup.h"
#include "gpu/context.h"
#include "io/image_io.h"
#include "relight/relight_state.h"
#include "render/obscurance_renderer.h"

namespace obscura::app {

struct RenderedFrame {
  // The AOVs asked for (every one the method keeps when none was), "denoised" with the denoiser,
  // and with `lightLayers` one "light.<name>" layer per light (obscurance method only).
  io::Image image;
  std::vector<std::uint32_t> display; // combined (denoised when denoising) tonemapped, RGBA8
  render::RenderStats stats;
  nlohmann::json method;   // the method and its settings as the metrics JSON says them
  std::string summary;     // the obscurance method's line for the terminal (dmax, rho, I_a, ...)
  // The obscurance method's per-light transport and lights (what relighting composes), when asked.
  std::optional<relight::RelightState> state;
};

// What renderFrame keeps beyond the AOVs.
struct FrameOutputs {
  bool lightLayers = false; // "light.<name>" layers in the image
  bool state = false;       // RenderedFrame::state
  bool allAovs = false;     // every AOV when none is named (an EXR's or an array's), else combined alone
};

// The paths --pt-correction asks for with these options: auto's count for --spp (none with path
// tracing or the denoiser, which it does not apply to), or the number given; InputError for
// anything else, or a count with path tracing or the denoiser.
std::uint32_t correctionPaths(const RenderOptions& o);

// InputError for options that cannot make a frame (an unknown AOV, --denoise with path tracing).
void checkFrameOptions(const RenderOptions& o);

// The stats as the metrics JSON says them: passes (gpu_ms, rays, mrays_per_s each), gpu_ms, rays,
// mrays_per_s, wall_s, device_bytes, truncated_traversals.
nlohmann::json statsJson(const render::RenderStats& stats);

// DeviceError when a traversal of the frame ran out of steps (the image would be wrong).
void checkTraversals(const render::RenderStats& stats);

// The options renderFrame reads beyond the shared ones (addRenderOptions): --aov, --exposure,
// --denoise.
void addFrameOptions(CLI::App& cmd, RenderOptions& o);

// Renders `scene` (with `bvh`, built for `context`) with `o`; chooses the camera and fills a
// missing size in `o`. The caller checks the traversals (checkTraversals), after printing the stats' notes.
RenderedFrame renderFrame(RenderOptions& o, const scene::Scene& scene, const bvh::Bvh& bvh, const gpu::Context& context,
                          const FrameOutputs& outputs, const render::ProgressFn& progress = nullptr);

} // namespace obscura::app
