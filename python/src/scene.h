// scene.h — obscura.Scene: a glTF scene opened once (loaded and checked, light groups made, names
// unique) that renders and sessions share; its BVH is built once per traversal the devices ask for.
#pragma once
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "bvh/bvh.h"
#include "gpu/context.h"
#include "scene/scene.h"

namespace obscura::python {

class Scene {
public:
  // app::loadScene's: `lightGroups` "node", "material" or a JSON file of groups.
  Scene(const std::string& path, const std::string& lightGroups);

  const std::string& path() const { return path_; }
  const std::string& lightGroups() const { return lightGroups_; }
  const scene::Scene& scene() const { return *scene_; }
  // The BVH `context`'s traversal wants (render::treeOptionsFor), built on first use.
  std::shared_ptr<const bvh::Bvh> treeFor(const gpu::Context& context) const;

private:
  std::string path_, lightGroups_;
  std::shared_ptr<const scene::Scene> scene_;
  mutable std::mutex treesMutex_;
  mutable std::map<std::uint32_t, std::shared_ptr<const bvh::Bvh>> trees_; // by render::Traversal
};

} // namespace obscura::python
