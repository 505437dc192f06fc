#include "relight/relight_state.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/error.h"
#include "io/image_io.h"
#include "io/json_file.h"
#include "shared/host_device.h"

namespace obscura::relight {
namespace {
namespace fs = std::filesystem;

nlohmann::json vec3Json(const glm::vec3& v) { return {v.x, v.y, v.z}; }

glm::vec3 vec3From(const nlohmann::json& j, const std::string& file, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !std::all_of(j.begin(), j.end(), [](const auto& x) { return x.is_number(); }))
    throw InputError(fmt::format("{}: {} must be an array of 3 numbers", file, what));
  return {j[0].get<float>(), j[1].get<float>(), j[2].get<float>()};
}

// state.json's fields but the transport; InputError naming `file` when one is missing or malformed.
RelightState stateFromJson(const nlohmann::json& json, const std::string& file) {
  RelightState state;
  state.document = json;
  try {
    if (!json.contains("version") || !json.at("version").is_number_integer() ||
        json.at("version").get<int>() < kOldestStateVersion || json.at("version").get<int>() > kStateVersion)
      throw InputError(fmt::format("{}: state version {} (this obscura reads versions {} to {}); render it again",
                                   file, json.contains("version") ? json.at("version").dump() : "missing",
                                   kOldestStateVersion, kStateVersion));
    state.scene = json.at("scene").get<std::string>();
    state.samples = json.at("samples").get<std::uint32_t>();
    state.settings = json.at("settings");
    for (const auto& l : json.at("lights")) {
      LightRecord r;
      r.name = l.at("name").get<std::string>();
      r.type = l.at("type").get<std::string>();
      r.emission = vec3From(l.at("emission"), file, "lights[].emission");
      r.ambientWeight = vec3From(l.at("ambient_weight"), file, "lights[].ambient_weight");
      state.lights.push_back(r);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: malformed state ({})", file, e.what()));
  }
  return state;
}

} // namespace

std::vector<glm::vec3> RelightState::emissions() const {
  std::vector<glm::vec3> out;
  for (const auto& l : lights) out.push_back(l.emission);
  return out;
}

std::vector<glm::vec3> RelightState::ambientWeights() const {
  std::vector<glm::vec3> out;
  for (const auto& l : lights) out.push_back(l.ambientWeight);
  return out;
}

std::size_t RelightState::lightIndex(const std::string& name, const std::string& where) const {
  for (std::size_t i = 0; i < lights.size(); ++i)
    if (lights[i].name == name) return i;
  std::vector<std::string> names;
  for (const auto& l : lights) names.push_back(l.name);
  throw InputError(fmt::format("{}: no light named '{}' (lights: {})", where, name, fmt::join(names, ", ")));
}

void saveState(const std::string& dir, const render::ObscuranceRenderer& renderer, const std::string& scenePath) {
  saveState(dir, renderer, renderer.transport(), scenePath);
}

nlohmann::json stateJson(const std::string& scenePath, std::uint32_t samples, const nlohmann::json& settings,
                         const glm::vec3& averageReflectance, const std::vector<LightRecord>& lights,
                         const render::Transport& transport) {
  nlohmann::json json = {{"version", kStateVersion},
                         {"scene", scenePath},
                         {"width", transport.width},
                         {"height", transport.height},
                         {"samples", samples},
                         {"specular", transport.specular},
                         {"settings", settings},
                         {"average_reflectance", vec3Json(averageReflectance)},
                         {"lights", nlohmann::json::array()}};
  for (const auto& l : lights)
    json["lights"].push_back({{"name", l.name}, {"type", l.type}, {"emission", vec3Json(l.emission)},
                              {"ambient_weight", vec3Json(l.ambientWeight)}});
  return json;
}

nlohmann::json stateJson(const render::ObscuranceRenderer& renderer, const std::string& scenePath) {
  const auto& lights = renderer.lights();
  const auto& s = renderer.settings();
  const nlohmann::json settings = {{"seed", s.seed}, {"shadow_rays", s.shadowRays}, {"obscurance_rays", s.obscuranceRays},
                                   {"dmax", renderer.dMax()}, {"rho", static_cast<int>(s.rho)}, {"systematic", s.systematic},
                                   {"colour_bleeding", s.colourBleeding}, {"dark_escapes", renderer.darkEscapes()},
                                   {"max_depth", s.maxDepth},
                                   {"vertex_rays_by_throughput", s.vertexRaysByThroughput},
                                   {"emission_samples", s.emissionSamples}, {"emission_at_edges", s.emissionAtEdges}};
  std::vector<LightRecord> records;
  for (std::size_t i = 0; i < lights.size(); ++i)
    records.push_back({lights.names[i], nameString(render::kLightTypeNames, lights.type(i)), renderer.emissions()[i],
                       renderer.ambient().weight[i]});
  render::Transport size; // the header's size and specular flag, without resolving the frame
  size.width = static_cast<int>(s.width);
  size.height = static_cast<int>(s.height);
  size.specular = renderer.specular();
  return stateJson(scenePath, renderer.samples(), settings, renderer.ambient().averageReflectance, records, size);
}

void saveState(const std::string& dir, const render::ObscuranceRenderer& renderer, const render::Transport& transport,
               const std::string& scenePath) {
  saveState(dir, stateJson(renderer, scenePath), transport);
}

void saveState(const std::string& dir, const nlohmann::json& state, const render::Transport& transport) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw InputError(fmt::format("{}: cannot create the state folder", dir));
  io::writeExr((fs::path(dir) / "transport.exr").string(), transport.toImage());
  const std::string path = (fs::path(dir) / "state.json").string(), temp = path + ".tmp";
  {
    std::ofstream out(temp);
    out << state.dump(2) << "\n";
    if (!out) throw InputError(fmt::format("{}: cannot write", path));
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::remove(temp.c_str());
    throw InputError(fmt::format("{}: cannot write", path));
  }
}

RelightState currentState(const render::ObscuranceRenderer& renderer, const std::string& scenePath) {
  RelightState state = stateFromJson(stateJson(renderer, scenePath), scenePath);
  state.transport = renderer.transport();
  return state;
}

void saveState(const std::string& dir, const RelightState& state) { saveState(dir, state.document, state.transport); }

RelightState loadState(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(fmt::format("{}: not a relighting state folder (it does not exist)", dir));
  const std::string jsonPath = (fs::path(dir) / "state.json").string();
  const std::string exrPath = (fs::path(dir) / "transport.exr").string();
  const nlohmann::json json =
      io::readJsonFile(jsonPath, "missing (not a state written by 'obscura render --save-state')");
  RelightState state = stateFromJson(json, jsonPath);
  try {
    const int width = json.at("width").get<int>(), height = json.at("height").get<int>();
    const bool specular = json.at("specular").get<bool>();
    std::vector<std::string> names;
    for (const auto& l : state.lights) names.push_back(l.name);
    if (!fs::exists(exrPath)) throw InputError(fmt::format("{}: missing", exrPath));
    io::Image image = io::readImage(exrPath);
    if (image.width != width || image.height != height)
      throw InputError(fmt::format("{}: {}x{} pixels, but {} says {}x{}", exrPath, image.width, image.height,
                                   jsonPath, width, height));
    state.transport = render::Transport::fromImage(image, names, specular, exrPath);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: malformed state ({})", jsonPath, e.what()));
  }
  return state;
}

} // namespace obscura::relight
