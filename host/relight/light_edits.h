// light_edits.h — the edits file of `obscura relight SCENE --edits edits.json`: a JSON list applied
// in order, each entry one of
//   {"light": NAME, "scale": S}            the light's intensity multiplier (absolute, starts at 1)
//   {"light": NAME, "color": [r, g, b]}    its RGB multipliers (absolute, start at 1, 1, 1)
//   {"add_light": {"type": "point"|"spot", "name": N, "position": [..], "color": [..],
//                  "intensity": I, "direction": [..], "inner_cone": a, "outer_cone": b}}
//   {"add_light": {"type": "quad", "name": N, "corner": [..], "edge1": [..], "edge2": [..],
//                  "emission": [r, g, b]}}     an emissive quad: a light and an object named N
//   {"remove_light": NAME}
//   {"move_light": NAME, "position": [..]}  a point or spot light an earlier edit added
//   {"move": NODE, "translate": [..], "rotate_deg": [..]}, {"remove": NODE},
//   {"insert": "other.gltf", "name": N, "translate": [..]}   (the path relative to the edits file)
// A light's emission is E_s = (scene's E_s) x scale x color, as if the glTF's emissive strength
// and factor (or the punctual light's intensity and colour) were edited.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/names.h"
#include "scene/scene.h"
#include "scene/scene_edit.h"
#include "io/json_fields.h"
#include "session/edit.h"

namespace obscura::relight {

// What an 'add_light' entry's "type" makes: a punctual light, or an emissive quad (geometry too).
enum class AddedLightType { Point, Spot, Quad };
inline constexpr NameTable<AddedLightType, 3> kAddedLightTypeNames{
    {{"point", AddedLightType::Point}, {"spot", AddedLightType::Spot}, {"quad", AddedLightType::Quad}}};

using session::Edit;

// Reads and checks the whole file before anything is rendered: malformed entries and names
// that do not exist at that point of the sequence (lights added or removed before it counted)
// are InputErrors naming the file and the entry. `lightNames` are the scene's lights, `areaLights`
// which of them are emissive meshes (removing one switches it off; its name stays), `objectNames`
// its objects. An insert's path is made absolute here and its glTF loaded (Edit::inserted).
// An added point or spot light: {"type": "point"|"spot", "name", "position", "color", "intensity",
// "direction", "inner_cone", "outer_cone"} in glTF KHR_lights_punctual units (also the view
// script's and panel's). InputError naming `at` when malformed.
scene::PunctualLight readAddedLight(const nlohmann::json& j, const io::JsonEntry& at);

// One entry's syntax, without checking that the names it uses exist: the edits file's entries
// and the window script's "panel" edits. InputError naming `at` when malformed.
Edit readEdit(const nlohmann::json& j, const io::JsonEntry& at);

std::vector<Edit> readEdits(const std::string& path, std::vector<std::string> lightNames,
                            std::vector<bool> areaLights, std::vector<std::string> objectNames);

} // namespace obscura::relight
