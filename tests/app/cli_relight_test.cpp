// `obscura render --save-state` and `obscura relight` as a user runs them: a saved render is
// relit with no scene and no ray; a scene is edited in order with one frame per edit and its
// figures; bad states and bad edits are clear errors naming the file (and the entry), exit 2,
// with nothing written.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "gpu_test.h"
#include "io/image_io.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kCornellLight = "light_rectangle_1"; // the Cornell box's emissive node

class CliRelight : public CliTest {
protected:
  // Renders the Cornell box with its relighting state in `state`, the EXR in render.exr.
  void renderWithState(const std::string& state = "state") {
    const auto r = runObscura("render " + cornellBox() + " --width 24 --height 24 --spp 2 --save-state " +
                              path(state) + " -o " + path("render.exr"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  static std::vector<float> combined(const io::Image& image) {
    std::vector<float> out;
    const int c = image.channelIndex("combined.R");
    EXPECT_GE(c, 0);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int k = 0; k < 3; ++k) out.push_back(image.at(x, y, c + k));
    return out;
  }
  void writeText(const std::string& name, const std::string& text) { std::ofstream(path(name)) << text; }
  // Each edits file is refused with exit 2, the file and `expected` in the message, and no frame.
  void expectEditsRefused(const std::vector<std::pair<json, std::string>>& cases) {
    for (const auto& [edits, expected] : cases) {
      SCOPED_TRACE(edits.dump());
      writeText("edits.json", edits.dump());
      const auto r = runObscura("relight " + cornellBox() + " --edits " + path("edits.json") + " -o " + path("out") +
                                " --width 16 --spp 1");
      EXPECT_EQ(r.exitCode, 2) << r.output;
      EXPECT_CONTAINS(r.output, "edits.json");
      EXPECT_CONTAINS(r.output, expected);
      EXPECT_FALSE(fs::exists(path("out"))) << "no partial frame";
    }
  }
};

TEST_F(CliRelight, SavedStateRecomposesTheRenderAndScalesALight) {
  renderWithState();
  const io::Image rendered = io::readImage(path("render.exr"));
  EXPECT_GE(rendered.channelIndex(std::string("light.") + kCornellLight + ".R"), 0) << "per-light EXR layer";

  auto r = runObscura("relight " + path("state") + " -o " + path("same.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto before = combined(rendered), same = combined(io::readImage(path("same.exr")));
  ASSERT_EQ(before.size(), same.size());
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_NEAR(same[i], before[i], 1e-5f * std::max(1.0f, before[i]));

  // A state of version 1 (before a light could carry its own indirect layer) reads as it did.
  fs::copy(path("state"), path("state-v1"));
  json v1 = json::parse(std::ifstream(path("state-v1") + "/state.json"));
  ASSERT_EQ(v1["version"], 2);
  v1["version"] = 1;
  std::ofstream(path("state-v1") + "/state.json") << v1.dump();
  r = runObscura("relight " + path("state-v1") + " -o " + path("same-v1.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(combined(io::readImage(path("same-v1.exr"))), same);

  r = runObscura("relight " + path("state") + " --light " + kCornellLight + "=2 -o " + path("double.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto doubled = combined(io::readImage(path("double.exr")));
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_NEAR(doubled[i], 2.0f * before[i], 1e-5f * std::max(1.0f, before[i]));

  // The box's only light off: nothing is lit, not even indirectly (I_a follows the edit).
  r = runObscura("relight " + path("state") + " --light " + kCornellLight + "=0 -o " + path("off.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (float v : combined(io::readImage(path("off.exr")))) EXPECT_EQ(v, 0.0f);

  r = runObscura("relight " + path("state") + " --light " + kCornellLight + "=1,1,0,0 -o " + path("red.png"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(fs::exists(path("red.png")));
}

TEST_F(CliRelight, BrokenStatesAreRefusedNamingTheFile) {
  renderWithState("good");
  const std::vector<std::string> inputs = {"render.exr", "good", "good/state.json", "good/transport.exr"};
  struct Case {
    const char* name;
    std::function<void(const fs::path&)> breakIt;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"missing-transport", [](const fs::path& d) { fs::remove(d / "transport.exr"); }, "transport.exr"},
      {"missing-json", [](const fs::path& d) { fs::remove(d / "state.json"); }, "state.json"},
      {"truncated-transport", [](const fs::path& d) { fs::resize_file(d / "transport.exr", fs::file_size(d / "transport.exr") / 2); },
       "transport.exr"},
      {"other-version", [](const fs::path& d) {
         json j = json::parse(std::ifstream(d / "state.json"));
         j["version"] = 99;
         std::ofstream(d / "state.json") << j.dump();
       }, "version"},
      {"other-size", [](const fs::path& d) {
         json j = json::parse(std::ifstream(d / "state.json"));
         j["width"] = 25;
         std::ofstream(d / "state.json") << j.dump();
       }, "transport.exr"},
      {"not-json", [](const fs::path& d) { std::ofstream(d / "state.json") << "{ nope"; }, "state.json"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path copy = dir_ / c.name;
    fs::copy(dir_ / "good", copy);
    c.breakIt(copy);
    const auto r = runObscura("relight " + copy.string() + " -o " + path("out.exr"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_CONTAINS(r.output, c.expected);
    EXPECT_FALSE(fs::exists(path("out.exr")));
    fs::remove_all(copy);
  }
  const auto r = runObscura("relight " + path("good") + " --light nosuch=1 -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "nosuch");
  EXPECT_CONTAINS(r.output, kCornellLight);
  EXPECT_EQ(strayFiles(inputs), std::vector<std::string>{});
}

TEST_F(CliRelight, SceneEditsWriteAFramePerEditAndTheirFigures) {
  writeText("edits.json", json::array({
                              {{"light", kCornellLight}, {"scale", 0.5}},
                              {{"light", kCornellLight}, {"color", {1.0, 0.5, 0.5}}},
                              {{"add_light", {{"type", "point"}, {"name", "bulb"}, {"position", {0.0, 1.0, 0.0}},
                                              {"color", {1, 1, 1}}, {"intensity", 2.0}}}},
                              {{"remove_light", "bulb"}},
                          }).dump());
  const auto r = runObscura("relight " + cornellBox() + " --edits " + path("edits.json") + " -o " + path("out") +
                            " --width 24 --height 24 --spp 2 --png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (int n = 0; n <= 4; ++n) {
    EXPECT_TRUE(fs::exists(path("out/frame-00" + std::to_string(n) + ".exr"))) << n;
    EXPECT_TRUE(fs::exists(path("out/frame-00" + std::to_string(n) + ".png"))) << n;
  }
  std::ifstream log(path("out/edits.jsonl"));
  std::vector<json> lines;
  for (std::string line; std::getline(log, line);) lines.push_back(json::parse(line));
  ASSERT_EQ(lines.size(), 4u);
  for (const auto& line : lines)
    for (const char* key : {"kind", "pixels_retraced", "rays", "gpu_ms", "total_ms"}) EXPECT_TRUE(line.contains(key)) << key;
  EXPECT_EQ(lines[0]["kind"], "scale");
  EXPECT_EQ(lines[0]["pixels_retraced"], 0);
  EXPECT_FALSE(lines[0]["rays"].contains("shadow")) << "a light edit traces no ray";
  EXPECT_EQ(lines[2]["kind"], "add_light");
  EXPECT_GT(lines[2]["rays"]["shadow"].get<double>(), 0.0);
  EXPECT_FALSE(lines[2]["rays"].contains("obscurance")) << "an added light traces only its shadow rays";
  // Halving the light halves the frame; removing the added bulb gives frame 2 back.
  const auto f0 = combined(io::readImage(path("out/frame-000.exr")));
  const auto f1 = combined(io::readImage(path("out/frame-001.exr")));
  const auto f2 = combined(io::readImage(path("out/frame-002.exr")));
  const auto f4 = combined(io::readImage(path("out/frame-004.exr")));
  for (std::size_t i = 0; i < f0.size(); ++i) {
    EXPECT_NEAR(f1[i], 0.5f * f0[i], 1e-5f * std::max(1.0f, f0[i]));
    EXPECT_NEAR(f4[i], f2[i], 1e-5f * std::max(1.0f, f2[i]));
  }
}

TEST_F(CliRelight, BadEditsAreRefusedNamingTheEntryBeforeAnyFrame) {
  // The command's side of a bad edits file: exit 2, the file and entry named, no frame. Every kind
  // of bad entry is checked in-process (EditsFile.BadEntriesAreRefusedNamingTheEntry).
  const std::vector<std::pair<json, std::string>> cases = {
      {json::array({{{"light", kCornellLight}, {"scale", 2}}, {{"light", "nosuch"}, {"scale", 2}}}), "entry 1"},
      {json::array({{{"remove_light", "b"}}}), "no light named 'b'"},
  };
  expectEditsRefused(cases);
}

// An emissive quad on the back wall: a light (its own layer, relit like any other) and an object
// (later edits may move or remove it); only the pixels its surface can change are retraced.
TEST_F(CliRelight, AddedEmissiveQuadIsALightAndAnObject) {
  writeText("edits.json", json::array({
                              {{"add_light", {{"type", "quad"}, {"name", "panel"}, {"corner", {-0.9, 0.1, -0.99}},
                                              {"edge1", {0.4, 0.0, 0.0}}, {"edge2", {0.0, 0.3, 0.0}},
                                              {"emission", {6.0, 6.0, 8.0}}}}},
                              {{"light", "panel"}, {"scale", 0.5}},
                              {{"move", "panel"}, {"translate", {0.5, 0.0, 0.0}}},
                          }).dump());
  const auto r = runObscura("relight " + cornellBox() + " --edits " + path("edits.json") + " -o " + path("out") +
                            " --width 32 --height 32 --spp 4");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  std::ifstream log(path("out/edits.jsonl"));
  std::vector<json> lines;
  for (std::string line; std::getline(log, line);) lines.push_back(json::parse(line));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0]["kind"], "add_light");
  EXPECT_GT(lines[0]["rays"]["shadow"].get<double>(), 0.0);
  EXPECT_GT(lines[0]["pixels_retraced"].get<int>(), 0);
  EXPECT_LT(lines[0]["pixels_retraced"].get<int>(), 32 * 32) << "only the pixels the quad's surface can change";
  EXPECT_EQ(lines[0]["bvh"]["kind"], "insert") << "its two triangles hung into the tree, not rebuilt";
  EXPECT_EQ(lines[1]["pixels_retraced"], 0);
  EXPECT_EQ(lines[2]["pixels_retraced"], 32 * 32) << "a moved emitter can change every pixel";
  auto layer = [&](int frame, const std::string& name) {
    const io::Image image = io::readImage(path("out/frame-00" + std::to_string(frame) + ".exr"));
    const int c = image.channelIndex(name + ".R");
    std::vector<float> out;
    if (c < 0) return out;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int k = 0; k < 3; ++k) out.push_back(image.at(x, y, c + k));
    return out;
  };
  EXPECT_TRUE(layer(0, "light.panel").empty());
  const auto panel = layer(1, "light.panel"), halved = layer(2, "light.panel");
  ASSERT_EQ(panel.size(), 32u * 32u * 3u);
  ASSERT_EQ(halved.size(), panel.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < panel.size(); ++i) {
    sum += panel[i];
    EXPECT_NEAR(halved[i], 0.5f * panel[i], 1e-5f * std::max(1.0f, panel[i]));
  }
  EXPECT_GT(sum / static_cast<double>(panel.size()), 0.01) << "the panel lights the room";
}

} // namespace
} // namespace obscura::test

namespace obscura::test {
namespace {

// The contract of geometry edits: the frame after `{"move": ...}` is statistically the frame
// `obscura render` makes of the glTF edited the same way (the node translated). Tolerance: the
// block-mean RMS difference (4x4 blocks below the lamp) of two fresh renders (seeds 11 and 12) of
// the edited glTF, times 3.
TEST_F(CliRelight, MovedObjectFrameMatchesARenderOfTheEditedGltf) {
  json gltf = json::parse(std::ifstream(repoPath("scenes/cornell-box/cornell-box.gltf")));
  for (auto& node : gltf["nodes"])
    if (node["name"] == "cube_2") node["translation"] = {0.35, 0.0, 0.3};
  for (const auto& buffer : gltf["buffers"]) // beside the edited copy, as the glTF names it
    fs::copy_file(repoPath("scenes/cornell-box/" + buffer["uri"].get<std::string>()),
                  path(buffer["uri"].get<std::string>()));
  writeText("edited.gltf", gltf.dump());
  writeText("edits.json", json::array({{{"move", "cube_2"}, {"translate", {0.35, 0.0, 0.3}}}}).dump());
  const std::string size = " --width 32 --height 32 --spp 32";
  auto r = runObscura("relight " + cornellBox() + " --edits " + path("edits.json") + " -o " + path("out") + size);
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (int seed : {11, 12}) { // with the edit session's I_a, the reached one
    r = runObscura("render " + path("edited.gltf") + " -o " + path("fresh" + std::to_string(seed) + ".exr") + size +
                   " --ambient reached --seed " + std::to_string(seed));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  auto blocks = [&](const std::string& file) {
    const auto c = combined(io::readImage(path(file)));
    std::vector<double> means;
    for (int by = 8; by < 32; by += 4) // below the lamp, whose edge pixels are the noisiest
      for (int bx = 0; bx < 32; bx += 4) {
        double sum = 0.0;
        for (int y = by; y < by + 4; ++y)
          for (int x = bx; x < bx + 4; ++x)
            for (int k = 0; k < 3; ++k) sum += c[(y * 32 + x) * 3 + k];
        means.push_back(sum / 48.0);
      }
    return means;
  };
  auto rms = [](const std::vector<double>& a, const std::vector<double>& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(sum / static_cast<double>(a.size()));
  };
  const auto a = blocks("fresh11.exr"), b = blocks("fresh12.exr"), moved = blocks("out/frame-001.exr"),
             before = blocks("out/frame-000.exr");
  const double spread = rms(a, b);
  EXPECT_LT(rms(moved, a), 3.0 * spread) << "seed-to-seed " << spread;
  EXPECT_GT(rms(before, a), 3.0 * spread) << "the move must show";
  std::ifstream log(path("out/edits.jsonl"));
  std::string line;
  std::getline(log, line);
  const json figures = json::parse(line);
  EXPECT_GT(figures["pixels_retraced"].get<int>(), 0);
  EXPECT_EQ(figures["bvh"]["kind"], "refit") << "a move refits the BVH";
  EXPECT_LT(figures["pixels_retraced"].get<int>(), 32 * 32) << "only the pixels the move can change";
}

TEST_F(CliRelight, RemovingTheOnlyEmitterLeavesADarkRoom) {
  // The lamp's triangles go, and with them its light: direct, indirect and seen emission all 0,
  // with no NaN from its zero-area emitters (both shadow sampling modes).
  writeText("edits.json", json::array({{{"remove", kCornellLight}}}).dump());
  for (const char* mode : {"selection", "per-light"}) {
    SCOPED_TRACE(mode);
    const auto r = runObscura("relight " + cornellBox() + " --edits " + path("edits.json") + " -o " + path(mode) +
                              " --width 24 --spp 2 --shadow-sampling " + mode);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (float v : combined(io::readImage(path(std::string(mode) + "/frame-001.exr")))) EXPECT_EQ(v, 0.0f);
  }
}

TEST_F(CliRelight, ObjectEditsNameObjectsThatExist) {
  const std::vector<std::pair<json, std::string>> cases = {
      {json::array({{{"move", "nosuch"}, {"translate", {0, 1, 0}}}}), "no object named 'nosuch'"},
      {json::array({{{"remove", "cube_1"}}, {{"remove", "cube_1"}}}), "entry 1"},
      {json::array({{{"insert", "missing.gltf"}, {"name", "x"}}}), "missing.gltf"},
      {json::array({{{"insert", repoPath("scenes/cornell-box/cornell-box.gltf")}, {"name", "cube_1"}}}), "exists"},
  };
  expectEditsRefused(cases);
}

TEST_F(CliRelight, CompareMeasuresTheErrorBetweenTwoRenders) {
  for (const char* name : {"a.exr", "b.exr"}) {
    const auto r = runObscura("render " + cornellBox() + " --width 16 --spp 1 -o " + path(name) +
                              (std::string(name) == "b.exr" ? " --seed 9" : ""));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  auto r = runObscura("compare " + path("a.exr") + " " + path("a.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_CONTAINS(r.output, "rmse 0 relmse 0");
  r = runObscura("compare " + path("a.exr") + " " + path("b.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(r.output.find("rmse 0 "), std::string::npos) << "two seeds differ: " << r.output;
  r = runObscura("compare " + path("a.exr") + " " + path("b.exr") + " --channel nosuch.R");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "a.exr");
}

TEST_F(CliRelight, RefittedBvhAfterAMoveTracesLikeBruteForceOnTheGpu) {
  for (const char* update : {"", " --refit"}) {
    const auto r = runObscura("bench-rays " + cornellBox() + " --rays 4096 --verify 4096 --move cube_2=0.3,0,0.2" +
                              update);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_CONTAINS(r.output, " 0 mismatches");
  }
  const auto bad = runObscura("bench-rays " + cornellBox() + " --rays 64 --move nosuch=1,0,0");
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_CONTAINS(bad.output, "nosuch");
}

TEST_F(CliRelight, InfoListsTheLightsEditsCanName) {
  const auto r = runObscura("info " + sharedScene("modern-hall/modern-hall.gltf"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_CONTAINS(r.output, "lights (13");
  EXPECT_CONTAINS(r.output, "light_rectangle_6");
  EXPECT_CONTAINS(r.output, "default dmax");
  EXPECT_CONTAINS(r.output, "cameras (1");
  EXPECT_CONTAINS(r.output, "objects (");
  const auto bad = runObscura("info " + path("nope.gltf"));
  EXPECT_EQ(bad.exitCode, 2) << bad.output;
  EXPECT_CONTAINS(bad.output, "nope.gltf");
}

} // namespace
} // namespace obscura::test
