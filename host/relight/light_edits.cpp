#include "relight/light_edits.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/json_file.h"
#include "io/json_fields.h"
#include "scene/gltf_loader.h"

namespace obscura::relight {
namespace {

using nlohmann::json;

using EntryContext = io::JsonEntry;

float number(const json& j, const char* key, const EntryContext& at) { return io::jsonNumber(j, key, at); }
glm::vec3 vec3(const json& j, const char* key, const EntryContext& at) { return io::jsonVec3(j, key, at); }
std::string text(const json& j, const char* key, const EntryContext& at) { return io::jsonText(j, key, at); }

void requireLight(const std::vector<std::string>& names, const std::string& name, const EntryContext& at) {
  if (std::find(names.begin(), names.end(), name) == names.end())
    at.fail(fmt::format("no light named '{}' at this point (lights: {})", name, fmt::join(names, ", ")));
}

} // namespace

scene::PunctualLight readAddedLight(const json& j, const io::JsonEntry& at) {
  if (!j.is_object()) at.fail("'add_light' must be an object");
  const AddedLightType type = io::jsonNamed(j, "type", kAddedLightTypeNames, at);
  if (type == AddedLightType::Quad) at.fail("an emissive quad is not a punctual light");
  scene::PunctualLight l;
  l.name = text(j, "name", at);
  l.type = type == AddedLightType::Point ? scene::PunctualType::Point : scene::PunctualType::Spot;
  l.position = vec3(j, "position", at);
  l.color = j.contains("color") ? vec3(j, "color", at) : glm::vec3(1.0f);
  l.intensity = number(j, "intensity", at);
  if (l.intensity < 0.0f || glm::any(glm::lessThan(l.color, glm::vec3(0.0f))))
    at.fail("intensity and color must not be negative");
  if (l.type == scene::PunctualType::Spot) {
    glm::vec3 d = vec3(j, "direction", at);
    if (glm::length(d) == 0.0f) at.fail("'direction' must not be zero");
    l.direction = glm::normalize(d);
    l.innerConeAngle = j.contains("inner_cone") ? number(j, "inner_cone", at) : 0.0f;
    l.outerConeAngle = j.contains("outer_cone") ? number(j, "outer_cone", at) : 0.7853982f;
    if (!(0.0f <= l.innerConeAngle && l.innerConeAngle < l.outerConeAngle && l.outerConeAngle <= 1.5707964f))
      at.fail("cones must satisfy 0 <= inner_cone < outer_cone <= pi/2 (radians, as glTF)");
  }
  return l;
}

namespace {

scene::EmissiveQuad addedQuad(const json& j, const EntryContext& at) {
  scene::EmissiveQuad q;
  q.name = text(j, "name", at);
  q.corner = vec3(j, "corner", at);
  q.edge1 = vec3(j, "edge1", at);
  q.edge2 = vec3(j, "edge2", at);
  q.emission = vec3(j, "emission", at);
  if (!(glm::length(glm::cross(q.edge1, q.edge2)) > 0.0f)) at.fail("'edge1' and 'edge2' span no area");
  if (glm::any(glm::lessThan(q.emission, glm::vec3(0.0f)))) at.fail("'emission' must not be negative");
  return q;
}

} // namespace

namespace {

void requireObject(const std::vector<std::string>& names, const std::string& name, const EntryContext& at) {
  if (std::find(names.begin(), names.end(), name) == names.end())
    at.fail(fmt::format("no object named '{}' at this point (objects: {})", name, fmt::join(names, ", ")));
}

} // namespace

Edit readEdit(const json& j, const io::JsonEntry& at) {
  if (!j.is_object()) at.fail("an edit must be an object");
  Edit e;
  e.entry = at.entry;
  if (j.contains("light")) {
    e.name = text(j, "light", at);
    if (j.contains("scale")) {
      e.kind = Edit::Kind::Scale;
      e.scale = number(j, "scale", at);
      if (e.scale < 0.0f) at.fail("'scale' must not be negative");
    } else if (j.contains("color")) {
      e.kind = Edit::Kind::Color;
      e.color = vec3(j, "color", at);
      if (glm::any(glm::lessThan(e.color, glm::vec3(0.0f)))) at.fail("'color' must not be negative");
    } else {
      at.fail("a light edit needs 'scale' or 'color'");
    }
  } else if (j.contains("add_light")) {
    const json& light = j.at("add_light");
    const bool quad = light.is_object() && light.contains("type") && light.at("type").is_string() &&
                      valueNamed(kAddedLightTypeNames, light.at("type").get<std::string>()) == AddedLightType::Quad;
    if (quad) {
      e.kind = Edit::Kind::AddQuad;
      e.quad = addedQuad(light, at);
      e.name = e.quad.name;
    } else {
      e.kind = Edit::Kind::AddLight;
      e.light = readAddedLight(light, at);
      e.name = e.light.name;
    }
  } else if (j.contains("remove_light")) {
    e.kind = Edit::Kind::RemoveLight;
    e.name = text(j, "remove_light", at);
  } else if (j.contains("move_light")) {
    e.kind = Edit::Kind::MoveLight;
    e.name = text(j, "move_light", at);
    e.position = vec3(j, "position", at);
  } else if (j.contains("move")) {
    e.kind = Edit::Kind::Move;
    if (!j.at("move").is_string()) at.fail("'move' must be an object's name");
    e.name = j.at("move").get<std::string>();
    e.translate = j.contains("translate") ? vec3(j, "translate", at) : glm::vec3(0.0f);
    e.rotateDegrees = j.contains("rotate_deg") ? vec3(j, "rotate_deg", at) : glm::vec3(0.0f);
  } else if (j.contains("remove")) {
    e.kind = Edit::Kind::Remove;
    e.name = text(j, "remove", at);
  } else if (j.contains("insert")) {
    e.kind = Edit::Kind::Insert;
    e.path = text(j, "insert", at);
    e.name = text(j, "name", at);
    e.translate = j.contains("translate") ? vec3(j, "translate", at) : glm::vec3(0.0f);
  } else {
    at.fail("unknown edit (known: light, add_light, remove_light, move_light, move, remove, insert)");
  }
  return e;
}

std::vector<Edit> readEdits(const std::string& path, std::vector<std::string> lightNames,
                            std::vector<bool> areaLights, std::vector<std::string> objectNames) {
  const json list = io::readJsonFile(path, "cannot read the edits file");
  if (!list.is_array()) throw InputError(fmt::format("{}: the edits must be a JSON list", path));
  std::vector<std::string> addedPunctual; // lights a move_light may move
  auto taken = [](const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  std::vector<Edit> edits;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const EntryContext at{path, i};
    Edit e = readEdit(list[i], at);
    // The names each edit refers to must exist at its point of the sequence.
    switch (e.kind) {
      case Edit::Kind::Scale:
      case Edit::Kind::Color: requireLight(lightNames, e.name, at); break;
      case Edit::Kind::AddQuad:
      case Edit::Kind::AddLight: {
        const bool quad = e.kind == Edit::Kind::AddQuad;
        if (quad) {
          // The quad is an object too: later edits may move or remove it.
          if (taken(objectNames, e.name)) at.fail(fmt::format("an object named '{}' exists already", e.name));
          objectNames.push_back(e.name);
        } else {
          addedPunctual.push_back(e.name);
        }
        if (taken(lightNames, e.name)) at.fail(fmt::format("a light named '{}' exists already", e.name));
        // Area lights come before punctual ones; only a punctual light's name goes on removal.
        lightNames.push_back(e.name);
        areaLights.push_back(quad);
        break;
      }
      case Edit::Kind::RemoveLight: {
        requireLight(lightNames, e.name, at);
        const auto k = static_cast<std::size_t>(std::find(lightNames.begin(), lightNames.end(), e.name) - lightNames.begin());
        if (!areaLights[k]) {
          lightNames.erase(lightNames.begin() + static_cast<std::ptrdiff_t>(k));
          areaLights.erase(areaLights.begin() + static_cast<std::ptrdiff_t>(k));
          std::erase(addedPunctual, e.name);
        }
        break;
      }
      case Edit::Kind::MoveLight:
        requireLight(lightNames, e.name, at);
        if (!taken(addedPunctual, e.name))
          at.fail(fmt::format("'{}' is not a point or spot light added by an earlier edit (only those move)", e.name));
        break;
      case Edit::Kind::Move: requireObject(objectNames, e.name, at); break;
      case Edit::Kind::Remove:
        requireObject(objectNames, e.name, at);
        objectNames.erase(std::find(objectNames.begin(), objectNames.end(), e.name));
        break;
      case Edit::Kind::Insert:
        if (std::filesystem::path(e.path).is_relative())
          e.path = (std::filesystem::path(path).parent_path() / e.path).string();
        if (!std::filesystem::exists(e.path)) at.fail(fmt::format("'{}': no such file", e.path));
        if (taken(objectNames, e.name)) at.fail(fmt::format("an object named '{}' exists already", e.name));
        objectNames.push_back(e.name);
        // Loaded (and so checked) before anything is rendered.
        e.inserted = std::make_shared<const scene::Scene>(scene::loadGltf(e.path));
        break;
    }
    edits.push_back(std::move(e));
  }
  return edits;
}

} // namespace obscura::relight
