// obscura remodel — the photographed room, relit and remodelled with the reflectance `recover`
// found [IVR §5] (recover/remodel.h):
//   obscura remodel DIR --edits edits.json -o out.{exr,png} [--spp N] [--bounces N] ...
// DIR is a `recover` output folder (reflectance.exr, recover.json). The room starts with the
// photographed lamps "shot0".."shotN-1" on, each as photographed; the edits are relight's format
// (relight/light_edits.h), applied in order:
//   {"light": "shot2", "scale": 0}, {"light": N, "color": [..]}   a lamp's intensity, colour
//   {"add_light": {"type": "point", "name": N, "position": [..], "intensity": I, "color": [..]}}
//   {"remove_light": N}
//   {"remove": NODE}          a real object: what it covered is re-rendered, its reflectance
//                             synthesized from the same surface elsewhere (texture_fill.h)
//   {"insert": "other.gltf", "name": N, "translate": [..]}   a virtual object (base colours)
// Moving a real object and emissive quads are refused (the moved object's own reflectance would
// have to be re-projected; quads are not point lamps). The EXR holds R, G, B and the layers
// reflectance.*, direct.*, indirect.* (per unit reflectance) and synthesized.id.
#include <chrono>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/scene_setup.h"
#include "core/error.h"
#include "io/image_io.h"
#include "io/json_file.h"
#include "recover/photo_set.h"
#include "recover/recovery_scene.h"
#include "recover/remodel.h"
#include "relight/light_edits.h"
#include "session/light_controls.h"
#include "session/scene_history.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/gltf_loader.h"
#include "scene/scene_edit.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

struct RemodelCommandOptions {
  std::string input, edits, output;
  float exposure = 0.0f;
  recover::RemodelOptions remodel;
  DeviceOptions device;
};

struct NamedLamp {
  std::string name;
  recover::Shot lamp;
};

glm::vec3 vec3Field(const nlohmann::json& j, const std::string& file, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !std::all_of(j.begin(), j.end(), [](const auto& x) { return x.is_number(); }))
    throw InputError(fmt::format("{}: {} must be an array of 3 numbers", file, what));
  return {j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
}

// The recovered room of a `recover` folder: reflectance.exr, and from recover.json the scene,
// the lamps and each object's mean reflectance.
struct RecoveredFolder {
  std::string scene;
  int camera = 0;
  std::vector<NamedLamp> lamps;
  recover::RecoveredRoom room;
};

RecoveredFolder readRecoveredFolder(const std::string& dir, const scene::Scene* sceneForNames = nullptr) {
  RecoveredFolder out;
  const std::string jsonPath = (fs::path(dir) / "recover.json").string();
  const nlohmann::json json = io::readJsonFile(jsonPath, "missing (not a folder written by 'obscura recover')");
  try {
    out.scene = json.at("scene").get<std::string>();
    out.camera = json.at("gltf_camera").get<int>();
    for (const auto& l : json.at("lamps")) {
      NamedLamp lamp;
      lamp.name = l.at("name").get<std::string>();
      lamp.lamp.position = vec3Field(l.at("position"), jsonPath, "lamps[].position");
      lamp.lamp.intensity = l.at("intensity").get<float>();
      lamp.lamp.color = vec3Field(l.at("color"), jsonPath, "lamps[].color");
      out.lamps.push_back(lamp);
    }
    if (sceneForNames) {
      const auto& objects = json.at("iterations").back().at("object_reflectance");
      for (const auto& obj : sceneForNames->objects) {
        if (!objects.contains(obj.name))
          throw InputError(fmt::format("{}: no reflectance for object '{}' of {}", jsonPath, obj.name, out.scene));
        out.room.objectReflectance.push_back(vec3Field(objects.at(obj.name), jsonPath, "object_reflectance"));
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: malformed ({}); written by an older 'obscura recover'?", jsonPath, e.what()));
  }
  return out;
}

void readReflectance(const std::string& dir, recover::RecoveredRoom& room, std::size_t objects) {
  const std::string path = (fs::path(dir) / "reflectance.exr").string();
  if (!fs::exists(path)) throw InputError(fmt::format("{}: missing", path));
  const io::Image image = io::readImage(path);
  const int r = image.channelIndex("R"), k = image.channelIndex("confidence.K"), f = image.channelIndex("filled.id"),
            o = image.channelIndex("object.id");
  if (r < 0 || k < 0 || f < 0 || o < 0 || image.channelIndex("G") != r + 1 || image.channelIndex("B") != r + 2)
    throw InputError(fmt::format("{}: needs the channels R, G, B, confidence.K, filled.id, object.id", path));
  // The reflectance of the surface each pixel's centre sees, before recover's footprint mix
  // (recover/reflectance_recovery.h: an edit changes what a footprint covers); a folder written
  // before that mix has R, G, B alone.
  const int surface = image.channelIndex("surface.R") >= 0 ? image.channelIndex("surface.R") : r;
  if (surface != r && (image.channelIndex("surface.G") != surface + 1 || image.channelIndex("surface.B") != surface + 2))
    throw InputError(fmt::format("{}: surface.R without surface.G and surface.B after it", path));
  room.width = image.width;
  room.height = image.height;
  const std::size_t n = image.channels.size();
  for (std::size_t p = 0; p < std::size_t(image.width) * image.height; ++p) {
    const float* v = &image.pixels[p * n];
    room.reflectance.emplace_back(v[surface], v[surface + 1], v[surface + 2]);
    const auto object = static_cast<std::int32_t>(std::lround(v[o]));
    if (object >= static_cast<std::int32_t>(objects))
      throw InputError(fmt::format("{}: object.id {} but the scene has {} objects", path, object, objects));
    room.object.push_back(object);
    room.measured.push_back(v[k] > 0.0f && std::lround(v[f]) == 0 ? 1 : 0);
  }
}

void runRemodel(const RemodelCommandOptions& o) {
  const std::string ext = io::extensionOf(o.output);
  if (ext != "exr" && ext != "png") throw InputError(fmt::format("{}: the output must be .exr or .png", o.output));
  // Everything is read and checked before anything is rendered or written.
  RecoveredFolder folder = readRecoveredFolder(o.input);
  LoadedScene loaded = loadScene(folder.scene);
  folder = readRecoveredFolder(o.input, &loaded.scene);
  readReflectance(o.input, folder.room, loaded.scene.objects.size());
  if (folder.camera < 0 || folder.camera >= static_cast<int>(loaded.scene.cameras.size()))
    throw InputError(fmt::format("{}: gltf_camera {} is not a camera of {}", o.input, folder.camera, folder.scene));
  std::vector<std::string> lightNames, objectNames;
  for (const auto& l : folder.lamps) lightNames.push_back(l.name);
  for (const auto& obj : loaded.scene.objects) objectNames.push_back(obj.name);
  const std::vector<session::Edit> edits =
      relight::readEdits(o.edits, lightNames, std::vector<bool>(lightNames.size(), false), objectNames);
  // The room's objects and lamps as the edits leave them: the same bookkeeping as an edit
  // session's, without a renderer (this frame is rendered once, at the end).
  session::SceneHistory room(loaded.scene, loaded.bvh);
  session::LightControls lamps;
  for (const auto& l : folder.lamps) {
    scene::PunctualLight lamp{.name = l.name, .type = scene::PunctualType::Point, .color = l.lamp.color,
                              .intensity = l.lamp.intensity, .position = l.lamp.position};
    lamps.insert(lamps.size(), {.name = l.name, .light = lamp});
  }
  for (const session::Edit& e : edits) {
    const std::string where = fmt::format("{}: entry {}", o.edits, e.entry);
    switch (e.kind) {
      case session::Edit::Kind::Scale: lamps.at(e.name).scale = e.scale; break;
      case session::Edit::Kind::Color: lamps.at(e.name).color = e.color; break;
      case session::Edit::Kind::AddLight:
        if (e.light.type != scene::PunctualType::Point)
          throw InputError(fmt::format("{}: remodel adds point lamps only (the photographs' lamp model)", where));
        lamps.insert(lamps.size(), {.name = e.name, .added = true, .light = e.light});
        break;
      case session::Edit::Kind::RemoveLight: lamps.remove(e.name); break;
      case session::Edit::Kind::MoveLight: lamps.at(e.name).light.position = e.position; break;
      case session::Edit::Kind::Remove:
      case session::Edit::Kind::Insert: room.apply(e, where); break;
      case session::Edit::Kind::Move:
        throw InputError(fmt::format("{}: moving a photographed object is not supported (its reflectance would "
                                     "have to be re-projected); remove it and insert a model instead",
                                     where));
      case session::Edit::Kind::AddQuad:
        throw InputError(fmt::format("{}: remodel adds point lamps only (the photographs' lamp model)", where));
    }
  }
  std::vector<recover::Shot> on;
  for (const session::LightControl& l : lamps) {
    recover::Shot lamp;
    lamp.position = l.light.position;
    lamp.intensity = l.light.intensity * l.scale;
    lamp.color = l.light.color * l.color;
    if (lamp.intensity > 0.0f && glm::any(glm::greaterThan(lamp.color, glm::vec3(0.0f)))) on.push_back(lamp);
  }
  if (on.empty()) throw InputError(fmt::format("{}: no lamp is left on", o.edits));
  const scene::Scene& edited = room.scene();
  const bvh::Bvh& editedBvh = room.bvh();
  recover::PhotoSet lampSet;
  lampSet.file = o.edits;
  lampSet.shots = on;
  recover::checkLamps(edited, editedBvh, lampSet);

  const std::shared_ptr<gpu::Context> contextHandle = commandContext(o.device);
  const gpu::Context& context = *contextHandle;
  const scene::Camera camera = loaded.scene.cameras[static_cast<std::size_t>(folder.camera)];
  const recover::RemodelledFrame frame =
      recover::renderRemodelled(context, folder.room, edited, editedBvh, camera, on, o.remodel);
  io::Image image;
  image.width = frame.width;
  image.height = frame.height;
  image.channels = {"R", "G", "B", "reflectance.R", "reflectance.G", "reflectance.B", "direct.R", "direct.G",
                    "direct.B", "indirect.R", "indirect.G", "indirect.B", "synthesized.id"};
  const std::size_t n = image.channels.size();
  image.pixels.assign(frame.radiance.size() * n, 0.0f);
  for (std::size_t p = 0; p < frame.radiance.size(); ++p) {
    float* v = &image.pixels[p * n];
    for (int c = 0; c < 3; ++c) {
      v[c] = frame.radiance[p][c];
      v[3 + c] = frame.reflectance[p][c];
      v[6 + c] = frame.direct[p][c];
      v[9 + c] = frame.indirect[p][c];
    }
    v[12] = float(frame.synthesized[p]);
  }
  if (ext == "exr") io::writeExr(o.output, image);
  else io::writePng(o.output, image, 0, o.exposure, 3);
  fmt::print(stderr, "remodel: {} edits, {} lamps on, {} pixels synthesized; {:.1f} s -> {}\n", edits.size(), on.size(),
             frame.synthesizedPixels, frame.seconds, o.output);
}

} // namespace

void addRemodelCommand(CLI::App& app) {
  auto o = std::make_shared<RemodelCommandOptions>();
  CLI::App* cmd = app.add_subcommand("remodel", "Relight and remodel a photographed room with its recovered reflectance "
                                                "(DIR from 'obscura recover' --edits edits.json -o out)");
  cmd->add_option("input", o->input, "a folder written by 'obscura recover'")->required();
  cmd->add_option("--edits", o->edits, "JSON list of edits applied in order (see 'obscura relight')")->required();
  cmd->add_option("-o,--output", o->output, "output image (.exr with layers, or .png)")->required();
  cmd->add_option("--spp", o->remodel.spp, "samples per pixel of the direct light")->check(CLI::Range(1u, 4096u));
  cmd->add_option("--seed", o->remodel.seed, "random seed");
  cmd->add_option("--gather-rays", o->remodel.gatherRays, "indirect light: gather rays per pixel")
      ->check(CLI::Range(1u, 4096u));
  cmd->add_option("--gather-smoothing", o->remodel.gatherSmoothing, "indirect light: smoothing radius on each surface")
      ->check(CLI::Range(0, 32));
  cmd->add_option("--bounces", o->remodel.bounces, "indirect light: gathers (bounces)")->check(CLI::Range(0u, 64u));
  cmd->add_option("--hidden-bounces", o->remodel.hiddenBounces,
                  "indirect light: path vertices through surfaces the camera does not see before the cut")
      ->check(CLI::Range(0u, recover::kMaxHiddenBounces));
  cmd->add_option("--exposure", o->exposure, "PNG exposure in stops");
  addDeviceOptions(*cmd, o->device);
  cmd->callback([o] { runRemodel(*o); });
}

} // namespace obscura::app
