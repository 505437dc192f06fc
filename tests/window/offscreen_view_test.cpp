// `obscura view --offscreen`: the window's frame loop with no window system. It must be the same
// loop: the same script gives the same frames, actions and screenshot as the window under Xvfb,
// with no DISPLAY at all; it ends with --frames or the script; every frame's log line has its
// wall and GPU ms; and what only a window can do is refused before anything runs.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "gpu_test.h"
#include "io/image_io.h"
#include "window/event_script.h"
#include "window/virtual_display.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kSize = " --width 64 --height 48 ";
constexpr const char* kNoWindowSystem = "env -u DISPLAY -u WAYLAND_DISPLAY ";

class OffscreenView : public CliTest {
protected:
  RunResult offscreen(const std::string& args) {
    return runObscura("view " + cornellBox() + kSize + "--offscreen " + args, kNoWindowSystem);
  }
  void writeScript(const json& events) { std::ofstream(path("events.json")) << events.dump(); }
  std::vector<json> log(const std::string& name) {
    std::vector<json> lines;
    std::ifstream in(path(name));
    for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
    return lines;
  }
  // Every frame the loop shows, in either target, is logged with what it cost.
  static void expectTimedFrames(const std::vector<json>& frames) {
    for (const auto& f : frames) {
      SCOPED_TRACE(f.dump());
      EXPECT_GT(f["wall_ms"].get<double>(), 0.0);
      // Every frame here traces a sample or edits (spp is never reached), so each has GPU work.
      EXPECT_GT(f["frame_gpu_ms"].get<double>(), 0.0);
      EXPECT_GE(f["wall_ms"].get<double>(), f["render_ms"].get<double>()) << "the whole frame holds its parts";
    }
  }
};

// A camera drag, a light edit and an object move, then a screenshot of the last frame (denoised:
// the denoiser's history follows the camera, so the loop's order matters).
json editingScript() {
  return json::array({{{"frame", 1}, {"drag", {8, 3}}, {"button", "left"}},
                      {{"frame", 3}, {"panel", {{"light", "light_rectangle_1"}, {"scale", 0.5}}}},
                      {{"frame", 4}, {"panel", {{"move", "cube_1"}, {"translate", {0.05, 0.0, 0.05}}}}}});
}

TEST_F(OffscreenView, SameScriptGivesTheWindowsFramesAndScreenshotWithoutADisplay) {
  writeScript(editingScript());
  const std::string common = "--spp 16 --frames 6 --no-panel --script " + path("events.json");
  VirtualDisplay display;
  ASSERT_FALSE(display.display().empty());
  const auto windowed = runObscura("view " + cornellBox() + kSize + common + " --log " + path("window.jsonl") +
                                       " --screenshot " + path("window.png"),
                                   "DISPLAY=" + display.display() + " ");
  ASSERT_EQ(windowed.exitCode, 0) << windowed.output;
  const auto unwindowed = offscreen(common + " --log " + path("offscreen.jsonl") + " --screenshot " + path("offscreen.png"));
  ASSERT_EQ(unwindowed.exitCode, 0) << unwindowed.output;

  const auto w = log("window.jsonl"), o = log("offscreen.jsonl");
  ASSERT_EQ(w.size(), 6u);
  ASSERT_EQ(o.size(), 6u);
  for (std::size_t i = 0; i < o.size(); ++i) {
    SCOPED_TRACE(i);
    for (const char* key : {"actions", "samples", "restarted", "preview", "rays", "pixels_retraced"})
      EXPECT_EQ(o[i][key], w[i][key]) << key;
    EXPECT_TRUE(w[i]["presented"]);
    EXPECT_FALSE(o[i]["presented"]) << "offscreen presents nothing";
  }
  EXPECT_EQ(o[1]["actions"], json::array({"camera_move"}));
  EXPECT_EQ(o[3]["actions"], json::array({"light_scale"}));
  EXPECT_EQ(o[4]["actions"], json::array({"move_object"}));
  expectTimedFrames(w);
  expectTimedFrames(o);

  // The same device work in the same order: the frames are equal to the byte (lavapipe is
  // deterministic here; the targets differ only in where the bytes go).
  const io::Image a = io::readImage(path("window.png")), b = io::readImage(path("offscreen.png"));
  ASSERT_EQ(a.width, 64);
  ASSERT_EQ(a.height, 48);
  EXPECT_EQ(a.pixels, b.pixels);
}

TEST_F(OffscreenView, RunsToTheScriptsEndAndLogsEveryFrame) {
  // No --frames: the run is the script's length, here to the last frame of a held key (3 + 2).
  writeScript(json::array({{{"frame", 1}, {"panel", {{"exposure", 0.5}}}},
                           {{"frame", 3}, {"key", "W"}, {"hold", 2}}}));
  const auto r = offscreen("--spp 16 --script " + path("events.json") + " --log " + path("frames.jsonl"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto frames = log("frames.jsonl");
  ASSERT_EQ(frames.size(), 5u);
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(frames[i]["frame"], i);
  EXPECT_EQ(frames[1]["actions"], json::array({"exposure"}));
  EXPECT_EQ(frames[3]["actions"], json::array({"camera_move"}));
  EXPECT_EQ(frames[4]["actions"], json::array({"camera_move"}));
  expectTimedFrames(frames);
  EXPECT_TRUE(strayFiles({"events.json", "frames.jsonl"}).empty()) << "no screenshot asked, none written";
}

TEST_F(OffscreenView, WhatOnlyAWindowHasIsRefusedBeforeTheSceneLoads) {
  const auto noEnd = offscreen("--spp 4");
  EXPECT_EQ(noEnd.exitCode, 2) << noEnd.output;
  EXPECT_CONTAINS(noEnd.output, "--offscreen needs an end");

  const auto panel = offscreen("--frames 2 --screenshot-ui --screenshot " + path("ui.png"));
  EXPECT_EQ(panel.exitCode, 2) << panel.output;
  EXPECT_CONTAINS(panel.output, "--offscreen draws no panel");

  writeScript(json::array({{{"frame", 1}, {"window", "resize"}, {"size", {80, 60}}}}));
  const auto resize = offscreen("--script " + path("events.json"));
  EXPECT_EQ(resize.exitCode, 2) << resize.output;
  EXPECT_CONTAINS(resize.output, "'resize' at frame 1 needs a window");
  EXPECT_FALSE(fs::exists(path("ui.png")));
  for (const auto& r : {noEnd, panel, resize}) EXPECT_EQ(r.output.find("triangles"), std::string::npos) << r.output;
}

TEST(ViewBenchmarkScript, ParsesAndRunsItsSegmentsToFrame145) {
  // tools/gpu/view_benchmark_script.json drives the GPU benchmark (docs/BENCHMARKS.md); the run is
  // its length. Its names (bench_bulb, light_rectangle_6, Mesh017) are checked when it runs on
  // modern-hall, which is too slow for a test here.
  const window::EventScript script(repoPath("tools/gpu/view_benchmark_script.json"));
  EXPECT_EQ(script.length(), 146u);
  std::size_t drags = 0, moves = 0;
  for (const auto& e : script.events()) {
    EXPECT_NE(e.kind, window::ScriptEvent::Kind::Window) << "it must run --offscreen";
    const bool edit = e.kind == window::ScriptEvent::Kind::Panel && e.action.kind == window::ViewerAction::Kind::Edit;
    drags += edit && e.action.edit.kind == session::Edit::Kind::MoveLight;
    moves += edit && e.action.edit.kind == session::Edit::Kind::Move;
  }
  EXPECT_EQ(drags, 30u);
  EXPECT_EQ(moves, 30u);
}

} // namespace
} // namespace obscura::test
