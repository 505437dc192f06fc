// obscura relight — relighting [IVR], two ways:
//   obscura relight DIR --light NAME=SCALE[,R,G,B] ... -o out.{exr,png}
//       re-composes a state saved by `render --save-state DIR`, with no scene and no ray;
//   obscura relight SCENE --edits edits.json -o DIR [render options] [--png]
//       renders SCENE, then applies the edits in order, writing DIR/frame-NNN.exr (000 = before
//       any edit) and DIR/edits.jsonl (per edit: kind, pixels retraced, rays and ms per pass).
#include <algorithm>
#include <chrono>
#include <deque>
#include <map>
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
#include "render/scene/scene_buffers.h"
#include "render/transport.h"
#include "scene/gltf_loader.h"
#include "scene/scene_edit.h"

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

nlohmann::json passFigures(const render::RenderStats& before, const render::RenderStats& after) {
  nlohmann::json rays = nlohmann::json::object(), ms = nlohmann::json::object();
  for (const auto& [name, pass] : after.passes) {
    const auto it = before.passes.find(name);
    const double gpuMs = pass.gpuMs - (it == before.passes.end() ? 0.0 : it->second.gpuMs);
    const auto n = pass.rays - (it == before.passes.end() ? 0 : it->second.rays);
    if (gpuMs <= 0.0 && n == 0) continue;
    rays[name] = n;
    ms[name] = gpuMs;
  }
  return {{"rays", rays}, {"gpu_ms", ms}};
}

void relightScene(RelightOptions& o) {
  if (o.edits.empty()) throw InputError(fmt::format("{}: relighting a scene needs --edits edits.json", o.input));
  if (o.render.method != "obscurance")
    throw InputError("--method: relighting keeps per-light transport, which only the obscurance method has");
  checkRenderOptions(o.render);
  LoadedScene loaded = loadScene(o.input, o.render.lightGroups, std::nullopt);
  applyBackground(o.render, loaded);
  const render::LightSet sceneLights = render::buildLightSet(loaded.scene);
  std::vector<bool> area;
  for (const auto& l : sceneLights.lights) area.push_back(l.info.x == gpu::kLightArea);
  std::vector<std::string> objectNames;
  for (const auto& obj : loaded.scene.objects) objectNames.push_back(obj.name);
  const std::vector<relight::Edit> edits = relight::readEdits(o.edits, sceneLights.names, area, objectNames);
  // Inserted glTFs are loaded (and so checked) before anything is rendered.
  std::map<std::size_t, scene::Scene> inserts;
  for (const auto& e : edits)
    if (e.kind == relight::Edit::Kind::Insert) inserts[e.entry] = scene::loadGltf(e.path);
  std::error_code ec;
  fs::create_directories(o.output, ec);
  if (ec || !fs::is_directory(o.output)) throw InputError(fmt::format("{}: cannot create the output folder", o.output));

  const scene::Camera camera = chooseCamera(loaded.scene, o.render.camera);
  chooseSize(o.render, camera);
  gpu::Context context(o.render.device.contextOptions());
  buildTreeFor(loaded, context);
  render::ObscuranceSettings settings = obscuranceSettings(o.render, camera);
  settings.spareLightSlots = static_cast<std::uint32_t>(std::count_if(
      edits.begin(), edits.end(), [](const relight::Edit& e) {
        return e.kind == relight::Edit::Kind::AddLight || e.kind == relight::Edit::Kind::AddQuad;
      }));
  // An added light and a geometry edit's probes follow the frame's kept rays (shadow rays, lobe hits).
  settings.keptRaySamples = settings.spp;
  // Each geometry edit makes the next scene; the renderer keeps a pointer to the current one.
  std::deque<scene::Scene> scenes;
  std::deque<bvh::Bvh> trees;
  render::ObscuranceRenderer renderer(context, loaded.scene, loaded.bvh, settings);
  renderer.prepareForEdits();
  const scene::Scene* current = &loaded.scene;
  const bvh::Bvh* currentBvh = &loaded.bvh;
  nlohmann::json bvhUpdate; // how the last geometry edit updated the BVH, for edits.jsonl
  auto geometryEdit = [&](const relight::Edit& e) {
    scene::Scene next = *current;
    const std::string where = fmt::format("{}: entry {}", o.edits, e.entry);
    std::vector<scene::Bounds> changed;
    if (e.kind == relight::Edit::Kind::Insert) {
      const std::size_t i = scene::insertObject(next, inserts.at(e.entry), e.name, e.translate);
      changed.push_back(scene::objectBounds(next, i));
    } else if (e.kind == relight::Edit::Kind::AddQuad) {
      const std::size_t i = scene::insertEmissiveQuad(next, e.quad);
      changed.push_back(scene::objectBounds(next, i));
    } else {
      const std::size_t i = scene::objectIndex(next, e.name, where);
      changed.push_back(scene::objectBounds(next, i));
      if (e.kind == relight::Edit::Kind::Move) {
        scene::moveObject(next, i, e.translate, e.rotateDegrees);
        changed.push_back(scene::objectBounds(next, i));
      } else {
        scene::removeObject(next, i);
      }
    }
    scenes.push_back(std::move(next));
    // A move or a removal keeps every triangle: the BVH is refitted; an insert (or a quad) adds
    // triangles and rebuilds it.
    const auto start = Clock::now();
    const bool refit = e.kind == relight::Edit::Kind::Move || e.kind == relight::Edit::Kind::Remove;
    if (refit) {
      trees.push_back(*currentBvh);
      bvh::refit(trees.back(), render::triangleSoup(scenes.back()));
    } else {
      trees.push_back(bvh::build(render::triangleSoup(scenes.back())));
    }
    bvhUpdate = {{"kind", refit ? "refit" : "rebuild"},
                 {"ms", std::chrono::duration<double, std::milli>(Clock::now() - start).count()}};
    current = &scenes.back();
    currentBvh = &trees.back();
    if (e.kind == relight::Edit::Kind::AddQuad) return renderer.addEmitter(scenes.back(), trees.back(), changed);
    return renderer.updateGeometry(scenes.back(), trees.back(), changed);
  };
  // After renderer.composeDisplay(): the PNG from the fast path's display bytes, then the full
  // compose for the EXR's AOVs and light layers.
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

  // The scene's own emissions, and each light's intensity and colour multipliers.
  std::vector<glm::vec3> base = renderer.emissions();
  std::vector<float> scale(base.size(), 1.0f);
  std::vector<glm::vec3> color(base.size(), glm::vec3(1.0f));
  auto emissionsNow = [&] {
    std::vector<glm::vec3> e;
    for (std::size_t i = 0; i < base.size(); ++i) e.push_back(base[i] * scale[i] * color[i]);
    return e;
  };
  std::ofstream log(fs::path(o.output) / "edits.jsonl");
  for (std::size_t n = 0; n < edits.size(); ++n) {
    const relight::Edit& e = edits[n];
    const render::RenderStats before = renderer.stats();
    const auto start = Clock::now();
    std::uint64_t retraced = 0;
    switch (e.kind) {
      case relight::Edit::Kind::Scale: scale[renderer.lightIndex(e.name)] = e.scale; break;
      case relight::Edit::Kind::Color: color[renderer.lightIndex(e.name)] = e.color; break;
      case relight::Edit::Kind::AddLight: {
        // Compose's emissions first: addLight appends the new light's own.
        renderer.setEmissions(emissionsNow());
        renderer.addLight(e.light);
        base.push_back(renderer.emissions().back());
        scale.push_back(1.0f);
        color.push_back(glm::vec3(1.0f));
        retraced = renderer.layout().pixels();
        break;
      }
      case relight::Edit::Kind::AddQuad: {
        // An area light: it goes before the punctual lights, at its light group's index.
        renderer.setEmissions(emissionsNow());
        retraced = geometryEdit(e);
        const auto i = static_cast<std::ptrdiff_t>(renderer.lightIndex(e.name));
        base.insert(base.begin() + i, renderer.emissions()[static_cast<std::size_t>(i)]);
        scale.insert(scale.begin() + i, 1.0f);
        color.insert(color.begin() + i, glm::vec3(1.0f));
        break;
      }
      case relight::Edit::Kind::RemoveLight: {
        const std::size_t i = renderer.lightIndex(e.name);
        const bool areaLight = renderer.lights().lights[i].info.x == gpu::kLightArea;
        renderer.setEmissions(emissionsNow());
        renderer.removeLight(i);
        if (areaLight) {
          scale[i] = 0.0f;
        } else {
          base.erase(base.begin() + static_cast<std::ptrdiff_t>(i));
          scale.erase(scale.begin() + static_cast<std::ptrdiff_t>(i));
          color.erase(color.begin() + static_cast<std::ptrdiff_t>(i));
        }
        break;
      }
      case relight::Edit::Kind::Move:
      case relight::Edit::Kind::Remove:
      case relight::Edit::Kind::Insert: retraced = geometryEdit(e); break;
    }
    renderer.setEmissions(emissionsNow());
    renderer.composeDisplay(o.exposure);
    const double totalMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    nlohmann::json line = {{"edit", n}, {"kind", e.kindName()}, {"name", e.name}, {"pixels_retraced", retraced}};
    line.update(passFigures(before, renderer.stats()));
    if (!bvhUpdate.is_null()) line["bvh"] = std::exchange(bvhUpdate, nlohmann::json());
    if (!line["bvh"].is_null() || e.kind == relight::Edit::Kind::AddLight) {
      // What the lights reach (CPU rays of the Reached ambient model), measured again for the edit
      // (an added light: its own, on a thread beside its GPU work).
      const auto reach = renderer.lastReachUpdate();
      line["reach"] = {{"rays", reach.rays}, {"ms", reach.ms}};
    }
    line["total_ms"] = totalMs;
    log << line.dump() << "\n";
    writeFrame(n + 1);
    fmt::print(stderr, "relight: edit {} ({} {}): {} pixels retraced, {:.1f} ms\n", n, e.kindName(), e.name, retraced,
               totalMs);
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
