// scene_setup.h — loading a scene and building its BVH, with the figures every command reports.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "bvh/bvh.h"
#include "scene/scene.h"

namespace obscura::app {

struct LoadedScene {
  scene::Scene scene;
  bvh::Bvh bvh;
  double loadSeconds = 0.0;
};

LoadedScene loadScene(const std::string& path);

// Scene statistics and BVH figures for the metrics JSON.
nlohmann::json sceneJson(const LoadedScene& loaded);
// One line for the terminal: triangles, lights, BVH build time, nodes, depth, SAH cost.
std::string sceneSummary(const LoadedScene& loaded);

} // namespace obscura::app
