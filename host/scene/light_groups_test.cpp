// Light groups: unique names, grouping by material and from a file keep every emissive triangle
// in exactly one group whose index the triangle names.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "scene/light_groups.h"

namespace obscura::scene {
namespace {

// Three emissive "nodes" of one triangle each: a and b share material 1, c has material 2.
Scene threeLamps() {
  Scene s;
  s.materials.resize(3);
  s.materials[1].name = "warm";
  s.materials[1].emission = glm::vec3(2.0f);
  s.materials[2].name = "cold";
  s.materials[2].emission = glm::vec3(1.0f, 1.0f, 3.0f);
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 4; ++i) s.triangles.push_back({0, 1, 2});
  s.triangleMaterial = {0, 1, 1, 2};
  s.triangleLightGroup = {~0u, 0, 1, 2};
  s.lightGroups = {{.name = "a", .triangles = {1}, .emission = glm::vec3(2.0f)},
                   {.name = "b", .triangles = {2}, .emission = glm::vec3(2.0f)},
                   {.name = "c", .triangles = {3}, .emission = glm::vec3(1.0f, 1.0f, 3.0f)}};
  return s;
}

void expectConsistent(const Scene& s) {
  std::size_t members = 0;
  for (std::uint32_t g = 0; g < s.lightGroups.size(); ++g)
    for (std::uint32_t t : s.lightGroups[g].triangles) {
      EXPECT_EQ(s.triangleLightGroup[t], g) << "triangle " << t;
      ++members;
    }
  EXPECT_EQ(members, 3u);
}

TEST(LightGroups, RepeatedNamesGetANumber) {
  Scene s = threeLamps();
  s.lightGroups[1].name.assign(1, 'a');
  s.punctualLights.push_back({.name = "a"});
  makeLightNamesUnique(s);
  EXPECT_EQ(s.lightGroups[0].name, "a");
  EXPECT_EQ(s.lightGroups[1].name, "a#2");
  EXPECT_EQ(s.punctualLights[0].name, "a#3");
}

TEST(LightGroups, ByMaterialMergesNodesOfOneMaterial) {
  Scene s = threeLamps();
  groupLightsByMaterial(s);
  ASSERT_EQ(s.lightGroups.size(), 2u);
  EXPECT_EQ(s.lightGroups[0].name, "warm");
  EXPECT_EQ(s.lightGroups[0].triangles, (std::vector<std::uint32_t>{1, 2}));
  EXPECT_EQ(s.lightGroups[1].name, "cold");
  EXPECT_EQ(s.lightGroups[1].emission, glm::vec3(1.0f, 1.0f, 3.0f));
  expectConsistent(s);
}

TEST(LightGroups, FileMergesTheNamedGroupsAndKeepsTheOthers) {
  Scene s = threeLamps();
  const auto path = std::filesystem::temp_directory_path() / "obscura_light_groups.json";
  std::ofstream(path) << R"({"pair": ["c", "a"]})";
  groupLightsFromFile(s, path.string());
  ASSERT_EQ(s.lightGroups.size(), 2u);
  EXPECT_EQ(s.lightGroups[0].name, "pair");
  EXPECT_EQ(s.lightGroups[0].triangles, (std::vector<std::uint32_t>{1, 3}));
  EXPECT_EQ(s.lightGroups[1].name, "b");
  expectConsistent(s);
  std::ofstream(path) << R"({"x": ["nosuch"]})";
  Scene t = threeLamps();
  EXPECT_THROW(groupLightsFromFile(t, path.string()), InputError);
  std::ofstream(path) << R"({"x": ["a"], "y": ["a"]})";
  EXPECT_THROW(groupLightsFromFile(t, path.string()), InputError);
  std::filesystem::remove(path);
}

} // namespace
} // namespace obscura::scene
