// scene_setup.h — loading a scene and building its BVH, with the figures every command reports.
#pragma once
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "scene/scene.h"

namespace obscura::app {

struct LoadedScene {
  scene::Scene scene;
  bvh::Bvh bvh;
  double loadSeconds = 0.0;
};

// `lightGroups`: "node" (one light per emissive mesh node, the default), "material" (one per
// emissive material) or a JSON file of groups (scene/light_groups.h). Light names are made unique.
// `tree`: how the BVH is built (the renderer's default; bench-rays may ask for spatial splits);
// nullopt leaves it to buildTreeFor, once the device is known.
LoadedScene loadScene(const std::string& path, const std::string& lightGroups = "node",
                      const std::optional<bvh::BuildOptions>& tree = bvh::BuildOptions{});

// Builds loaded.bvh as the traversal `context` runs wants it (render::treeOptionsFor: spatial
// splits for a GPU's binary layout).
void buildTreeFor(LoadedScene& loaded, const gpu::Context& context);

// Scene statistics and BVH figures for the metrics JSON.
nlohmann::json sceneJson(const LoadedScene& loaded);
// One line for the terminal: triangles, lights, BVH build time, nodes, depth, SAH cost.
std::string sceneSummary(const LoadedScene& loaded);

} // namespace obscura::app
