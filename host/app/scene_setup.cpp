#include "app/scene_setup.h"

#include <chrono>

#include <fmt/core.h>

#include "render/scene_data/bvh_layout.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/gltf_loader.h"
#include "scene/light_groups.h"
#include "scene/scene_edit.h"

namespace obscura::app {

LoadedScene loadScene(const std::string& path, const std::string& lightGroups,
                      const std::optional<bvh::BuildOptions>& tree) {
  LoadedScene loaded;
  auto start = std::chrono::steady_clock::now();
  loaded.scene = scene::loadGltf(path);
  if (lightGroups == "material") scene::groupLightsByMaterial(loaded.scene);
  else if (lightGroups != "node") scene::groupLightsFromFile(loaded.scene, lightGroups);
  scene::makeLightNamesUnique(loaded.scene);
  scene::makeObjectNamesUnique(loaded.scene);
  loaded.loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (tree) loaded.bvh = bvh::build(render::triangleSoup(loaded.scene), *tree);
  return loaded;
}

void buildTreeFor(LoadedScene& loaded, const gpu::Context& context) {
  loaded.bvh = bvh::build(render::triangleSoup(loaded.scene), render::treeOptionsFor(render::traversalFor(context)));
}

nlohmann::json sceneJson(const LoadedScene& loaded) {
  const auto& s = loaded.scene;
  const auto& b = loaded.bvh.stats;
  return {{"path", s.sourcePath},
          {"triangles", s.triangles.size()},
          {"vertices", s.positions.size()},
          {"materials", s.materials.size()},
          {"textures", s.textures.size()},
          {"light_groups", s.lightGroups.size()},
          {"punctual_lights", s.punctualLights.size()},
          {"cameras", s.cameras.size()},
          {"degenerate_triangles_dropped", s.stats.degenerateTrianglesDropped},
          {"bounds_min", {s.bounds.lo.x, s.bounds.lo.y, s.bounds.lo.z}},
          {"bounds_max", {s.bounds.hi.x, s.bounds.hi.y, s.bounds.hi.z}},
          {"load_s", loaded.loadSeconds},
          {"bvh",
           {{"build_s", b.buildSeconds},
            {"nodes", b.nodeCount},
            {"leaves", b.leafCount},
            {"max_depth", b.maxDepth},
            {"sah_cost", b.sahCost},
            {"wide_sah_cost", b.wideSahCost},
            {"median_fallbacks", b.medianFallbacks},
            {"spatial_splits", b.spatialSplits},
            {"triangle_references", b.references},
            {"bytes", loaded.bvh.nodes.size() * sizeof(gpu::BvhNode) +
                          loaded.bvh.triangles.size() * sizeof(gpu::BvhTriangle)}}}};
}

std::string sceneSummary(const LoadedScene& loaded) {
  const auto& s = loaded.scene;
  const auto& b = loaded.bvh.stats;
  const std::string spatial = b.spatialSplits == 0 ? std::string()
                                                   : fmt::format(", {} spatial splits storing {} triangle references",
                                                                 b.spatialSplits, b.references);
  return fmt::format("scene: {} triangles ({} degenerate dropped), {} materials, {} textures, {} light "
                     "groups, {} punctual lights; loaded in {:.3f} s\n"
                     "bvh: built in {:.3f} s, {} nodes, {} leaves, depth {}, SAH cost {:.2f} (binary), {:.2f} (8-wide){}",
                     s.triangles.size(), s.stats.degenerateTrianglesDropped, s.materials.size(),
                     s.textures.size(), s.lightGroups.size(), s.punctualLights.size(), loaded.loadSeconds,
                     b.buildSeconds, b.nodeCount, b.leafCount, b.maxDepth, b.sahCost, b.wideSahCost, spatial);
}

} // namespace obscura::app
