// obscura relight — relighting [IVR], two ways:
//   obscura relight DIR --light NAME=SCALE[,R,G,B] ... -o out.{exr,png}
//       re-composes a state saved by `render --save-state DIR`, with no scene and no ray;
//   obscura relight SCENE --edits edits.json -o DIR [render options] [--png]
//       renders SCENE, then applies the edits in order, writing DIR/frame-NNN.exr (000 = before
//       any edit) and DIR/edits.jsonl (per edit: kind, pixels retraced, rays and ms per pass).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/render_options.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "relight/light_edits.h"
#include "relight/relight_state.h"
#include "render/scene_data/bvh_layout.h"
#include "render/scene_data/light_set.h"
#include "render/transport.h"
#include "session/edit_session.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct RelightOptions {
  std::string input;                 // a state folder or a glTF scene
  std::string output;
  std::vector<std::string> lights;   // NAME=SCALE[,R,G,B]
  std::string edits;
  bool png = false;
  float exposure = 0.0f;
  RenderOptions render;
};

struct LightSetting {
  std::string name;
  float scale = 1.0f;
  glm::vec3 color{1.0f};
};

// NAME=SCALE or NAME=SCALE,R,G,B (the last '=' splits, so names may hold one).
LightSetting parseLightSetting(const std::string& text) {
  const auto eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--light {}: expected NAME=SCALE or NAME=SCALE,R,G,B", text));
  LightSetting s;
  s.name = text.substr(0, eq);
  std::vector<float> values;
  std::stringstream list(text.substr(eq + 1));
  std::string item;
  while (std::getline(list, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stof(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError(fmt::format("--light {}: '{}' is not a number", text, item));
    }
  }
  if (values.size() != 1 && values.size() != 4)
    throw InputError(fmt::format("--light {}: expected NAME=SCALE or NAME=SCALE,R,G,B", text));
  for (float v : values)
    if (!std::isfinite(v) || v < 0.0f) throw InputError(fmt::format("--light {}: values must be finite and >= 0", text));
  s.scale = values[0];
  if (values.size() == 4) s.color = glm::vec3(values[1], values[2], values[3]);
  return s;
}

void relightState(const RelightOptions& o) {
  const std::string ext = io::extensionOf(o.output);
  if (ext != "exr" && ext != "png") throw InputError(fmt::format("{}: the output must be .exr or .png", o.output));
  if (!o.edits.empty())
    throw InputError(fmt::format("--edits needs a scene (edits that trace rays); {} is a saved state", o.input));
  const auto start = Clock::now();
  const relight::RelightState state = relight::loadState(o.input);
  std::vector<glm::vec3> emissions = state.emissions();
  for (const auto& text : o.lights) {
    const LightSetting s = parseLightSetting(text);
    const std::size_t i = state.lightIndex(s.name, "--light " + text);
    emissions[i] = state.lights[i].emission * s.scale * s.color;
  }
  const auto loaded = Clock::now();
  io::Image image = render::composeTransport(state.transport, emissions, state.ambientWeights());
  const auto composed = Clock::now();
  if (ext == "exr") {
    io::appendChannels(image, render::lightLayers(state.transport, emissions, state.ambientWeights()));
    io::writeExr(o.output, image);
  } else {
    io::writePng(o.output, image, 0, o.exposure, 3);
  }
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
  fmt::print(stderr, "relight: {} lights, {}x{}; read {:.1f} ms, compose {:.1f} ms (host), total {:.1f} ms -> {}\n",
             state.lights.size(), state.transport.width, state.transport.height, ms(start, loaded),
             ms(loaded, composed), ms(start, Clock::now()), o.output);
}

void relightScene(RelightOptions& o) {
  if (o.edits.empty()) throw InputError(fmt::format("{}: relighting a scene needs --edits edits.json", o.input));
  if (o.render.method != render::Method::Obscurance)
    throw InputError("--method: relighting keeps per-light transport, which only the obscurance method has");
  checkRenderOptions(o.render);
  LoadedScene loaded = loadScene(o.input, o.render.lightGroups, std::nullopt);
  applyBackground(o.render, loaded);
  const render::LightSet sceneLights = render::buildLightSet(loaded.scene);
  std::vector<bool> area;
  for (std::size_t i = 0; i < sceneLights.lights.size(); ++i) area.push_back(sceneLights.type(i) == render::LightType::Area);
  std::vector<std::string> objectNames;
  for (const auto& obj : loaded.scene.objects) objectNames.push_back(obj.name);
  const std::vector<relight::Edit> edits = relight::readEdits(o.edits, sceneLights.names, area, objectNames);
  std::error_code ec;
  fs::create_directories(o.output, ec);
  if (ec || !fs::is_directory(o.output)) throw InputError(fmt::format("{}: cannot create the output folder", o.output));

  const scene::Camera camera = chooseCamera(loaded.scene, o.render.camera);
  chooseSize(o.render, camera);
  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.render.device);
  const gpu::Context& context = *contextHandle;
  buildTreeFor(loaded, context);
  const auto spareLights = static_cast<std::uint32_t>(std::count_if(edits.begin(), edits.end(), [](const relight::Edit& e) {
    return e.kind == relight::Edit::Kind::AddLight || e.kind == relight::Edit::Kind::AddQuad;
  }));
  session::EditSession session(context, std::move(loaded.scene), std::move(loaded.bvh),
                               session::editSettings(obscuranceSettings(o.render, camera), spareLights),
                               render::treeOptionsFor(render::traversalFor(context)));
  render::ObscuranceRenderer& renderer = session.renderer();
  // After composeDisplay: the PNG from the fast path's display bytes, then the full compose for
  // the EXR's AOVs and light layers.
  auto writeFrame = [&](std::size_t n) {
    if (renderer.stats().truncatedTraversals > 0)
      throw DeviceError("traversals ran out of steps (kMaxTraversalSteps); the frame would be wrong");
    const fs::path stem = fs::path(o.output) / fmt::format("frame-{:03}", n);
    const auto& layout = renderer.layout();
    if (o.png)
      io::writePngRgba8(stem.string() + ".png", static_cast<int>(layout.width), static_cast<int>(layout.height),
                        renderer.display());
    renderer.compose(o.exposure);
    io::Image image = renderer.image();
    io::appendChannels(image, renderer.lightLayers());
    io::writeExr(stem.string() + ".exr", image);
  };
  renderer.reset();
  renderer.iterate(renderer.settings().spp);
  renderer.composeDisplay(o.exposure);
  writeFrame(0);

  std::ofstream log(fs::path(o.output) / "edits.jsonl");
  for (std::size_t n = 0; n < edits.size(); ++n) {
    const relight::Edit& e = edits[n];
    session::EditReport report = session.apply(e, fmt::format("{}: entry {}", o.edits, e.entry));
    session.composeDisplay(report, o.exposure);
    nlohmann::json line = report.json();
    line["edit"] = n;
    log << line.dump() << "\n";
    writeFrame(n + 1);
    fmt::print(stderr, "relight: edit {} ({} {}): {} pixels retraced, {:.1f} ms\n", n, report.kind, report.name,
               report.pixelsRetraced, report.totalMs);
  }
}

} // namespace

void addRelightCommand(CLI::App& app) {
  auto options = std::make_shared<RelightOptions>();
  CLI::App* cmd = app.add_subcommand(
      "relight", "Relight a saved render (DIR --light NAME=SCALE[,R,G,B] -o out) or apply edits to a scene "
                 "(SCENE --edits edits.json -o DIR)");
  cmd->add_option("input", options->input, "a state folder from 'render --save-state', or a glTF scene")->required();
  cmd->add_option("-o,--output", options->output, "output image (state) or output folder (scene)")->required();
  cmd->add_option("--light", options->lights,
                  "NAME=SCALE[,R,G,B]: the light's intensity multiplier and RGB colour multipliers (state mode)");
  cmd->add_option("--edits", options->edits, "JSON list of edits applied in order (scene mode)");
  cmd->add_flag("--png", options->png, "also write frame-NNN.png, tonemapped on the GPU (scene mode)");
  cmd->add_option("--exposure", options->exposure, "PNG exposure in stops");
  addRenderOptions(*cmd, options->render);
  addDeviceOptions(*cmd, options->render.device);
  cmd->callback([options] {
    if (fs::is_directory(options->input)) relightState(*options);
    else relightScene(*options);
  });
}

} // namespace obscura::app
