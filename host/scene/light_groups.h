// light_groups.h — which emissive triangles are edited together as one light (relighting's
// unit, one basis buffer each [SPEC §3]). The loader makes one group per emissive mesh node,
// named by the node (light<N> when it has none); these regroup them.
#pragma once
#include <string>

#include "scene/scene.h"

namespace obscura::scene {

// Makes every light name unique across groups and punctual lights: a repeated name gets "#2",
// "#3", ... in scene order, so that edits can name any light.
void makeLightNamesUnique(Scene& scene);

// One group per emissive MATERIAL (named by the material) instead of per node.
void groupLightsByMaterial(Scene& scene);

// Groups from a JSON file mapping a new group name to the names of the groups (nodes) it merges:
//   {"ceiling": ["lamp.001", "lamp.002"], "desk": ["desk_lamp"]}
// Groups not named stay as they are. InputError naming the file for an unknown or repeated name.
void groupLightsFromFile(Scene& scene, const std::string& path);

} // namespace obscura::scene
