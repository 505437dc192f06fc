// scene_history.h — the scene being edited and its BVH, one version per geometry edit, and the
// choice of how the BVH follows an edit: a move or a removal keeps every triangle, so the tree is
// refitted, above the object's triangles only (bvh/incremental_refit.h); an emissive quad's two
// triangles are hung into it (bvh/insert.h); an insert adds many triangles, so the tree is rebuilt
// with the options the device's traversal wants (render/scene_data/bvh_layout.h). A renderer
// holds pointers to the newest version; the one before stays until dropPrevious(), once the
// renderer has moved on to the new one.
#pragma once
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "bvh/bvh.h"
#include "bvh/incremental_refit.h"
#include "scene/scene.h"
#include "session/edit.h"

namespace obscura::session {

struct BvhUpdate {
  enum class Kind : std::uint8_t {
    Rebuild, // built anew
    Refit,   // the tree before, its boxes above the object's triangles refitted
    Insert,  // an added quad hung into the tree before (bvh/insert.h)
  };
  Kind kind = Kind::Rebuild;
  double ms = 0.0;        // host wall time of the update
  std::size_t nodes = 0;  // refitted: the nodes above the object's triangles (bvh/incremental_refit.h)
};

// What a geometry edit changed.
struct GeometryChange {
  std::vector<scene::Bounds> changed; // world boxes of the object's old and new places
  std::size_t object = 0;             // the object it edited (inserted: the new one)
  BvhUpdate bvh;
};

class SceneHistory {
public:
  SceneHistory(scene::Scene scene, bvh::Bvh bvh, bvh::BuildOptions rebuildOptions = {});

  const scene::Scene& scene() const { return scenes_.back(); }
  const bvh::Bvh& bvh() const { return trees_.back(); }

  // Applies a geometry edit (Edit::changesGeometry: Move, Remove, Insert, AddQuad) to a copy of
  // the current scene, which becomes current with its BVH updated. InputError naming `where` for
  // an object that does not exist or a name taken.
  GeometryChange apply(const Edit& edit, const std::string& where);
  // Forgets every version but the current one (nothing may point at them any more).
  void dropPrevious();

private:
  // An added quad (object `object` of `next`) into a copy of the current tree; false when it has
  // no room.
  bool insertQuad(const scene::Scene& next, std::size_t object, bvh::Bvh& tree);
  // An object's triangles: their indices and vertices, as the refit and the insert take them.
  struct ObjectTriangles {
    std::vector<std::uint32_t> ids;
    bvh::TriangleSoup soup;
  };
  static ObjectTriangles objectTriangles(const scene::Scene& scene, std::size_t object);

  std::deque<scene::Scene> scenes_; // a deque: its elements stay where they are as it grows
  std::deque<bvh::Bvh> trees_;
  bvh::BuildOptions rebuildOptions_;
  std::optional<bvh::IncrementalRefit> refitter_; // for trees_.back()
};

} // namespace obscura::session
