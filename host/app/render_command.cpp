// obscura render SCENE -o out.{exr,png} [--width --height --spp --aov NAME... --metrics m.json]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/render_options.h"
#include "app/render_frame.h"
#include "app/render_part.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "gpu/buffer.h"
#include "io/image_io.h"
#include "render/aovs.h"
#include "render/obscurance_renderer.h"
#include "relight/relight_state.h"

namespace obscura::app {
namespace {

void printProgress(std::uint32_t done, std::uint32_t total, double seconds, std::uint64_t raysPerSample) {
  double rate = seconds > 0 ? static_cast<double>(raysPerSample) * done / seconds / 1e6 : 0.0;
  double eta = done > 0 ? seconds / done * (total - done) : 0.0;
  std::fprintf(stderr, "\rrender: %3.0f%%  %6.2f Mrays/s  ETA %5.1f s ", 100.0 * done / total, rate, eta);
  if (done == total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

// Fails now, before any work, when `path` cannot be written (its folder is missing, is a file,
// or refuses a new file): a late failure would leave a finished image and no metrics.
void checkWritable(const std::string& path) {
  std::string probe = path + ".probe.tmp";
  {
    std::ofstream out(probe);
    if (!out) throw InputError(fmt::format("{}: cannot write metrics here", path));
  }
  std::remove(probe.c_str());
}

void writeMetrics(const std::string& path, const nlohmann::json& json) {
  std::string temp = path + ".tmp";
  {
    std::ofstream out(temp);
    if (!out) throw InputError(fmt::format("{}: cannot write metrics", path));
    out << json.dump(2) << "\n";
    if (!out) throw InputError(fmt::format("{}: cannot write metrics", path));
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    throw InputError(fmt::format("{}: cannot write metrics", path));
  }
}

// Writes the image (EXR layers or PNG of one AOV) and the metrics; fails on truncated traversals.
// `display`, when given, is the GPU-tonemapped combined image, written as the PNG of `combined`.
void writeOutputs(const RenderOptions& o, const io::Image& image, const render::RenderStats& stats,
                  const gpu::Context& context, const LoadedScene& loaded, const nlohmann::json& method,
                  const std::vector<std::uint32_t>* display = nullptr) {
  for (const auto& note : stats.notes) fmt::print(stderr, "note: {}\n", note);
  checkTraversals(stats);

  io::Image selected = render::selectAovs(image, o.aovs);
  if (io::extensionOf(o.output) == "exr") {
    io::writeExr(o.output, selected);
  } else if (display && !display->empty() &&
             (o.aovs.empty() || o.aovs.front() == "combined" || o.aovs.front() == "denoised")) {
    io::writePngRgba8(o.output, image.width, image.height, *display);
  } else {
    // A corrected frame (--pt-correction) shows its corrected layer where combined is asked for.
    std::string first = o.aovs.empty() ? "combined" : o.aovs.front();
    if (first == "combined" && image.channelIndex("corrected.R") >= 0) first = "corrected";
    const auto channels = render::aovChannels(first);
    io::writePng(o.output, image, image.channelIndex(channels.front()), o.exposure,
                 static_cast<int>(channels.size()));
  }

  const nlohmann::json figures = statsJson(stats);
  const double totalMs = figures["gpu_ms"], mrays = figures["mrays_per_s"];
  fmt::print(stderr, "render: {}x{}, {} spp, {} rays in {:.1f} ms GPU ({:.2f} Mrays/s), {:.2f} s wall -> {}\n",
             o.width, o.height, o.spp, figures["rays"].get<std::uint64_t>(), totalMs, mrays, stats.wallSeconds,
             o.output);
  if (!o.metrics.empty()) {
    nlohmann::json json = {
        {"device", {{"name", context.info().name}, {"driver", context.info().driver},
                    {"type", context.info().type}, {"api", context.info().apiVersion}}},
        {"scene", sceneJson(loaded)},
        {"image", {{"width", o.width}, {"height", o.height}, {"spp", o.spp}, {"seed", o.seed}, {"output", o.output}}},
        {"method", method}};
    json.update(figures);
    writeMetrics(o.metrics, json);
  }
}

void runRender(RenderOptions& o) {
  if (isPartRender(o)) {
    renderPart(o);
    return;
  }
  std::string ext = io::extensionOf(o.output);
  if (ext != "exr" && ext != "png")
    throw InputError(fmt::format("{}: the output must be .exr or .png", o.output));
  checkFrameOptions(o);
  if (!o.metrics.empty()) checkWritable(o.metrics);
  if (!o.saveState.empty() && o.method == render::Method::PathTrace)
    throw InputError("--save-state: only the obscurance method keeps per-light transport (--method obscurance)");

  LoadedScene loaded = loadScene(o.scenePath, o.lightGroups, std::nullopt);
  applyBackground(o, loaded);
  warnIfUnlit(loaded);

  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.device);
  const gpu::Context& context = *contextHandle;
  fmt::print(stderr, "device: {} ({})\n", context.info().name, context.info().driver);
  buildTreeFor(loaded, context);
  fmt::print(stderr, "{}\n", sceneSummary(loaded));

  const bool exr = ext == "exr";
  render::ProgressFn progress;
  if (::isatty(STDERR_FILENO)) {
    // The rays of one sample, for the rate (renderFrame has chosen the size by the first call).
    progress = [&](auto done, auto total, auto seconds) {
      printProgress(done, total, seconds,
                    std::uint64_t(o.width) * o.height * (1 + o.obscurance.shadowRays + o.obscurance.obscuranceRays));
    };
  }
  const RenderedFrame frame = renderFrame(
      o, loaded.scene, loaded.bvh, context,
      {.lightLayers = exr && o.aovs.empty(), .state = !o.saveState.empty(), .allAovs = exr}, progress);
  if (!frame.summary.empty()) fmt::print(stderr, "{}\n", frame.summary);
  if (frame.state) relight::saveState(o.saveState, *frame.state);
  writeOutputs(o, frame.image, frame.stats, context, loaded, frame.method,
               o.method == render::Method::PathTrace ? nullptr : &frame.display);
}

} // namespace

void addRenderCommand(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render a glTF scene headless to EXR (all AOVs) or PNG");
  cmd->add_option("scene", options->scenePath, "glTF 2.0 scene (.gltf or .glb)")->required();
  cmd->add_option("-o,--output", options->output, "output image, .exr (AOV layers) or .png (tonemapped)")->required();
  useStillImageDefaults(*options);
  addRenderOptions(*cmd, *options);
  addFrameOptions(*cmd, *options);
  cmd->add_option("--metrics", options->metrics, "write device, scene, BVH and per-pass figures as JSON");
  cmd->add_option("--save-state", options->saveState,
                  "write the relighting state to this folder (per-light transport as EXR layers + JSON), for "
                  "'obscura relight DIR'");
  cmd->add_option("--samples", options->partSamples,
                  "A:B: render only samples A (included) to B (excluded) of --spp, as a part of a farm render "
                  "(written as sums to -o part.exr; 'obscura merge' adds the parts up; tools/farm/)");
  cmd->add_option("--tile", options->partTile,
                  "I/T: render only the I-th (0-based) of T strips of whole rows, as a part of a farm render "
                  "(with or without --samples)");
  addDeviceOptions(*cmd, options->device);
  cmd->callback([options] { runRender(*options); });
}

} // namespace obscura::app
