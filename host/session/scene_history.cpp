#include "session/scene_history.h"

#include <chrono>
#include <stdexcept>

#include "bvh/insert.h"
#include "render/scene_data/scene_buffers.h"
#include "scene/scene_edit.h"

namespace obscura::session {

SceneHistory::SceneHistory(scene::Scene scene, bvh::Bvh bvh, bvh::BuildOptions rebuildOptions)
    : rebuildOptions_(rebuildOptions) {
  scenes_.push_back(std::move(scene));
  trees_.push_back(std::move(bvh));
  refitter_.emplace(trees_.back());
}

GeometryChange SceneHistory::apply(const Edit& e, const std::string& where) {
  using Kind = Edit::Kind;
  if (!e.changesGeometry()) throw std::logic_error("SceneHistory::apply: not a geometry edit");
  scene::Scene next = scenes_.back();
  GeometryChange change;
  if (e.kind == Kind::Insert) {
    if (!e.inserted) throw std::logic_error("SceneHistory::apply: an insert without its scene");
    change.object = scene::insertObject(next, *e.inserted, e.name, e.translate);
    change.changed.push_back(scene::objectBounds(next, change.object));
  } else if (e.kind == Kind::AddQuad) {
    change.object = scene::insertEmissiveQuad(next, e.quad);
    change.changed.push_back(scene::objectBounds(next, change.object));
  } else {
    change.object = scene::objectIndex(next, e.name, where);
    change.changed.push_back(scene::objectBounds(next, change.object));
    if (e.kind == Kind::Move) {
      scene::moveObject(next, change.object, e.translate, e.rotateDegrees);
      change.changed.push_back(scene::objectBounds(next, change.object));
    } else {
      scene::removeObject(next, change.object);
    }
  }
  const auto start = std::chrono::steady_clock::now();
  bvh::Bvh tree;
  if (e.kind == Kind::Move || e.kind == Kind::Remove) {
    // The object's triangles only (they have vertices of their own): the nodes above them.
    const ObjectTriangles moved = objectTriangles(next, change.object);
    tree = trees_.back();
    change.bvh.kind = BvhUpdate::Kind::Refit;
    change.bvh.nodes = refitter_->refit(tree, moved.ids, moved.soup).size();
  } else if (e.kind == Kind::AddQuad && insertQuad(next, change.object, tree)) {
    change.bvh.kind = BvhUpdate::Kind::Insert;
  } else {
    tree = bvh::build(render::triangleSoup(next), rebuildOptions_);
    refitter_.emplace(tree);
  }
  change.bvh.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  scenes_.push_back(std::move(next));
  trees_.push_back(std::move(tree));
  return change;
}

bool SceneHistory::insertQuad(const scene::Scene& next, std::size_t object, bvh::Bvh& tree) {
  // Its two triangles hung into the tree before (bvh/insert.h), the boxes above them refitted.
  const ObjectTriangles quad = objectTriangles(next, object);
  tree = trees_.back();
  if (!bvh::insertTriangles(tree, quad.ids, quad.soup)) return false;
  refitter_.emplace(tree);
  refitter_->refit(tree, quad.ids, quad.soup);
  return true;
}

SceneHistory::ObjectTriangles SceneHistory::objectTriangles(const scene::Scene& scene, std::size_t object) {
  const scene::SceneObject& o = scene.objects[object];
  ObjectTriangles out;
  for (std::uint32_t id = o.firstTriangle; id < o.firstTriangle + o.triangleCount; ++id) {
    const glm::uvec3& t = scene.triangles[id];
    out.ids.push_back(id);
    out.soup.v0.push_back(scene.positions[t.x]);
    out.soup.v1.push_back(scene.positions[t.y]);
    out.soup.v2.push_back(scene.positions[t.z]);
  }
  return out;
}

void SceneHistory::dropPrevious() {
  while (scenes_.size() > 1) {
    scenes_.pop_front();
    trees_.pop_front();
  }
}

} // namespace obscura::session
