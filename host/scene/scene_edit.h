// scene_edit.h — the object edits of remodelling [IVR §3.3]: move, remove and insert objects
// (glTF mesh-node instances, Scene::objects) in a loaded scene. The renderer then retraces only
// the pixels the changed boxes can affect (ObscuranceRenderer::updateGeometry).
#pragma once
#include <cstddef>
#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace obscura::scene {

// Makes object names unique: a repeated name gets "#2", "#3", ... in node order.
void makeObjectNamesUnique(Scene& scene);

// The index of the object named `name`; InputError naming `where` and listing the objects.
std::size_t objectIndex(const Scene& scene, const std::string& name, const std::string& where);

// World bounds of object `index`'s triangles (empty for a removed object).
Bounds objectBounds(const Scene& scene, std::size_t index);

// Rotates object `index` by `rotateDegrees` (about x, then y, then z) around its origin (its world
// transform's translation), then translates it; positions, normals, world transform and the
// scene's bounds follow.
void moveObject(Scene& scene, std::size_t index, glm::vec3 translate, glm::vec3 rotateDegrees);

// Removes object `index`: its triangles collapse to one point, so they are never hit, and every
// index (triangles, lights, objects) stays; the object is marked removed, so its name no longer
// finds it (objectIndex) and an insert may take it, as in an edits file's sequence. An emissive
// object's light then has no area and contributes nothing, as a scene without it renders.
void removeObject(Scene& scene, std::size_t index);

// Inserts every triangle of `other` as one object `name`, translated by `translate`; its materials
// and textures are appended. InputError when `other` emits light (edits add lights with
// add_light) or the name exists.
std::size_t insertObject(Scene& scene, const Scene& other, const std::string& name, glm::vec3 translate);

// An emissive quad (relight's {"add_light": {"type": "quad", ...}}): a parallelogram at `corner`
// spanned by `edge1` and `edge2`, emitting `emission` (radiance) from the side cross(edge1, edge2)
// points to, reflecting nothing (black, matte).
struct EmissiveQuad {
  std::string name;
  glm::vec3 corner{0.0f}, edge1{1.0f, 0.0f, 0.0f}, edge2{0.0f, 0.0f, 1.0f};
  glm::vec3 emission{1.0f};
};

// Inserts `quad` as object `name` with a light group of that name, the last one. InputError when
// the edges span no area, the emission is negative, or an object or light group of that name
// exists.
std::size_t insertEmissiveQuad(Scene& scene, const EmissiveQuad& quad);

} // namespace obscura::scene
