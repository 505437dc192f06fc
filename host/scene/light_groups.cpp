#include "scene/light_groups.h"

#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/json_file.h"

namespace obscura::scene {
namespace {

constexpr std::uint32_t kNoGroup = ~0u;

// Rebuilds lightGroups and triangleLightGroup from a group index per old group (kNoGroup:
// unchanged, keeps its own) — groups keep the order of their first member.
void regroup(Scene& scene, const std::vector<std::string>& newName) {
  std::vector<LightGroup> groups;
  std::map<std::string, std::uint32_t> byName;
  std::vector<std::uint32_t> remap(scene.lightGroups.size());
  for (std::size_t g = 0; g < scene.lightGroups.size(); ++g) {
    const std::string& name = newName[g].empty() ? scene.lightGroups[g].name : newName[g];
    auto [it, added] = byName.try_emplace(name, static_cast<std::uint32_t>(groups.size()));
    if (added) groups.push_back({.name = name, .triangles = {}, .emission = scene.lightGroups[g].emission});
    remap[g] = it->second;
    auto& into = groups[it->second].triangles;
    into.insert(into.end(), scene.lightGroups[g].triangles.begin(), scene.lightGroups[g].triangles.end());
  }
  for (auto& g : scene.triangleLightGroup)
    if (g != kNoGroup) g = remap[g];
  scene.lightGroups = std::move(groups);
}

} // namespace

void makeLightNamesUnique(Scene& scene) {
  UniqueNames names;
  for (auto& g : scene.lightGroups) names.apply(g.name);
  for (auto& l : scene.punctualLights) names.apply(l.name);
}

void groupLightsByMaterial(Scene& scene) {
  // A group's E_s is its first triangle's material emission; grouping by material keeps every
  // member's unit radiance 1 where the material is uniform.
  // A node whose triangles mix emissive materials is split by material.
  std::vector<LightGroup> split;
  std::vector<std::string> splitNames;
  for (std::size_t g = 0; g < scene.lightGroups.size(); ++g) {
    std::map<std::uint32_t, std::vector<std::uint32_t>> byMaterial;
    for (std::uint32_t t : scene.lightGroups[g].triangles) byMaterial[scene.triangleMaterial[t]].push_back(t);
    if (byMaterial.empty()) byMaterial[kNoGroup] = {};
    for (auto& [m, tris] : byMaterial) {
      const std::string name = m == kNoGroup ? scene.lightGroups[g].name : scene.materials[m].name;
      const glm::vec3 emission = m == kNoGroup ? scene.lightGroups[g].emission : scene.materials[m].emission;
      for (std::uint32_t t : tris) scene.triangleLightGroup[t] = static_cast<std::uint32_t>(split.size());
      split.push_back({.name = name, .triangles = std::move(tris), .emission = emission});
      splitNames.push_back(name);
    }
  }
  scene.lightGroups = std::move(split);
  regroup(scene, splitNames);
}

void groupLightsFromFile(Scene& scene, const std::string& path) {
  const nlohmann::json json = io::readJsonFile(path, "cannot read the light groups file");
  if (!json.is_object()) throw InputError(fmt::format("{}: expected an object {{\"group\": [\"light\", ...]}}", path));
  std::map<std::string, std::size_t> index;
  for (std::size_t g = 0; g < scene.lightGroups.size(); ++g) index[scene.lightGroups[g].name] = g;
  std::vector<std::string> newName(scene.lightGroups.size());
  std::set<std::string> assigned;
  for (const auto& [group, members] : json.items()) {
    if (!members.is_array() || members.empty())
      throw InputError(fmt::format("{}: \"{}\" must list the light groups it merges", path, group));
    for (const auto& m : members) {
      if (!m.is_string()) throw InputError(fmt::format("{}: \"{}\": members must be names", path, group));
      const std::string name = m.get<std::string>();
      const auto it = index.find(name);
      if (it == index.end())
        throw InputError(fmt::format("{}: \"{}\": no emissive node named '{}'", path, group, name));
      if (!assigned.insert(name).second)
        throw InputError(fmt::format("{}: '{}' is assigned to two groups", path, name));
      newName[it->second] = group;
    }
  }
  regroup(scene, newName);
}

} // namespace obscura::scene
