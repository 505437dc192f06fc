// The edits file of `relight --edits` (relight/light_edits.h), read in-process: every malformed
// entry and every name that does not exist at its point of the sequence is refused naming the
// file and the entry, before anything renders. (CliRelight checks that the command exits 2 and
// writes nothing for such a file.)
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "gpu_test.h"
#include "relight/light_edits.h"
#include "scene/gltf_loader.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kLamp = "light_rectangle_1"; // the Cornell box's emissive node

class EditsFile : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("obscura-edits-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    const scene::Scene cornell = scene::loadGltf(repoPath("scenes/cornell-box/cornell-box.gltf"));
    for (const auto& obj : cornell.objects) objects_.push_back(obj.name);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<session::Edit> read(const json& edits) {
    const std::string file = (dir_ / "edits.json").string();
    std::ofstream(file) << edits.dump();
    return relight::readEdits(file, {kLamp}, {true}, objects_);
  }
  // `edits` is refused with the file and `expected` in the message.
  void expectRefused(const json& edits, const std::string& expected) {
    SCOPED_TRACE(edits.dump());
    try {
      read(edits);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("edits.json"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }

  fs::path dir_;
  std::vector<std::string> objects_;
};

TEST_F(EditsFile, BadEntriesAreRefusedNamingTheEntry) {
  const json bulb = {{"type", "point"}, {"name", "b"}, {"position", {0, 1, 0}}, {"intensity", 1}};
  expectRefused(json::array({{{"light", kLamp}, {"scale", 2}}, {{"light", "nosuch"}, {"scale", 2}}}), "entry 1");
  expectRefused(json::array({{{"light", kLamp}}}), "entry 0");
  expectRefused(json::array({{{"light", kLamp}, {"scale", -1}}}), "negative");
  expectRefused(json::array({{{"add_light", {{"type", "point"}, {"name", "b"}}}}}), "position");
  expectRefused(json::array({{{"remove_light", "b"}}}), "no light named 'b'");
  expectRefused(json::array({{{"teleport", "x"}}}), "unknown edit");
  expectRefused(json::array({{{"add_light", {{"type", "laser"}, {"name", "b"}, {"position", {0, 1, 0}}, {"intensity", 1}}}}}),
                "'type' is point, spot or quad");
  expectRefused(json::object({{"light", kLamp}}), "list");
  expectRefused(json::array({{{"add_light", {{"type", "quad"}, {"name", "q"}, {"corner", {0, 0, 0}},
                                             {"edge1", {1, 0, 0}}, {"edge2", {2, 0, 0}}, {"emission", {1, 1, 1}}}}}}),
                "span no area");
  expectRefused(json::array({{{"add_light", {{"type", "quad"}, {"name", "q"}, {"corner", {0, 0, 0}},
                                             {"edge1", {1, 0, 0}}, {"edge2", {0, 1, 0}}}}}}),
                "'emission' is missing");
  expectRefused(json::array({{{"add_light", {{"type", "quad"}, {"name", "cube_1"}, {"corner", {0, 0, 0}},
                                             {"edge1", {1, 0, 0}}, {"edge2", {0, 1, 0}}, {"emission", {1, 1, 1}}}}}}),
                "an object named 'cube_1'");
  // Names follow the sequence: a removed light or object is gone for the entries after it.
  expectRefused(json::array({{{"add_light", bulb}}, {{"remove_light", "b"}}, {{"light", "b"}, {"scale", 1}}}),
                "entry 2");
  expectRefused(json::array({{{"remove", "cube_1"}}, {{"move", "cube_1"}}}), "no object named 'cube_1'");
  // Only a point or spot light an earlier edit added moves.
  expectRefused(json::array({{{"move_light", kLamp}, {"position", {0, 1, 0}}}}), "added by an earlier edit");
  expectRefused(json::array({{{"add_light", bulb}}, {{"move_light", "b"}}}), "position");
}

TEST_F(EditsFile, EntriesBecomeTheSessionsEdits) {
  const auto edits = read(json::array(
      {{{"light", kLamp}, {"color", {1, 0.5, 0.25}}},
       {{"add_light", {{"type", "point"}, {"name", "b"}, {"position", {0, 1, 0}}, {"intensity", 2}}}},
       {{"move_light", "b"}, {"position", {0.5, 1, 0}}},
       {{"move", "cube_1"}, {"translate", {0.1, 0, 0}}, {"rotate_deg", {0, 30, 0}}},
       {{"remove_light", "b"}}}));
  ASSERT_EQ(edits.size(), 5u);
  EXPECT_EQ(edits[0].kind, session::Edit::Kind::Color);
  EXPECT_EQ(edits[0].color, glm::vec3(1.0f, 0.5f, 0.25f));
  EXPECT_EQ(edits[1].kind, session::Edit::Kind::AddLight);
  EXPECT_EQ(edits[1].light.intensity, 2.0f);
  EXPECT_EQ(edits[2].kind, session::Edit::Kind::MoveLight);
  EXPECT_EQ(edits[2].position, glm::vec3(0.5f, 1.0f, 0.0f));
  EXPECT_EQ(edits[3].rotateDegrees, glm::vec3(0.0f, 30.0f, 0.0f));
  EXPECT_EQ(edits[4].kindName(), "remove_light");
  EXPECT_EQ(edits[4].entry, 4u);
}

} // namespace
} // namespace obscura::test
