// Object edits by name: a removed object is no longer found by its name, and its name is free for
// an insert, as the edits file's reader (relight/light_edits.h) already counts names.
#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/scene_edit.h"

namespace obscura::scene {
namespace {

// One triangle per object, named as given.
Scene triangles(std::initializer_list<const char*> names) {
  Scene s;
  s.materials.resize(1);
  for (const char* name : names) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    const float x = static_cast<float>(s.objects.size());
    s.positions.insert(s.positions.end(), {{x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}});
    s.normals.insert(s.normals.end(), 3, glm::vec3(0, 0, 1));
    s.uvs.insert(s.uvs.end(), 3, glm::vec2(0));
    s.objects.push_back({.name = name, .firstTriangle = static_cast<std::uint32_t>(s.triangles.size()), .triangleCount = 1});
    s.triangles.push_back({base, base + 1, base + 2});
    s.triangleMaterial.push_back(0);
    s.triangleLightGroup.push_back(~0u);
  }
  return s;
}

TEST(SceneEdit, RemovedObjectIsNoLongerFoundByNameAndItsNameIsFree) {
  Scene s = triangles({"table", "chair"});
  removeObject(s, objectIndex(s, "chair", "test"));
  EXPECT_TRUE(s.objects[1].removed);
  try {
    objectIndex(s, "chair", "edits.json: entry 3");
    FAIL() << "a removed object was found by its name";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no object named 'chair' (objects: table)"), std::string::npos) << e.what();
  }
  const std::size_t inserted = insertObject(s, triangles({"chair"}), "chair", glm::vec3(0, 0, 2));
  EXPECT_EQ(inserted, 2u);
  EXPECT_EQ(objectIndex(s, "chair", "test"), 2u); // the new one, not the removed one
  EXPECT_THROW(insertObject(s, triangles({"x"}), "table", glm::vec3(0)), InputError); // a live name stays taken
}

} // namespace
} // namespace obscura::scene
