// `obscura view` as a user runs it, in a window on an X server of the test's own (Xvfb) and
// lavapipe: the screenshot equals the headless render, a light edit is one compose pass that traces
// nothing, a camera move restarts accumulation with a preview frame, an object move retraces only
// the dirty pixels, the window survives resizing, minimising and closing mid-run, and bad input is
// refused before a window opens. Every run has the validation layer on (ctest sets
// OBSCURA_VALIDATE=1; runObscura fails a test on any message).
#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "io/image_io.h"
#include "window/virtual_display.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kLight = "light_rectangle_1"; // the Cornell box's lamp
constexpr int kSize = 48;

class CliView : public CliTest {
protected:
  RunResult view(const std::string& args) {
    EXPECT_FALSE(display_.display().empty());
    return runObscura("view " + cornellBox() + " --width " + std::to_string(kSize) + " --height " +
                          std::to_string(kSize) + " " + args,
                      "DISPLAY=" + display_.display() + " ");
  }
  void writeScript(const json& events) { std::ofstream(path("events.json")) << events.dump(); }
  std::vector<json> log() {
    std::vector<json> lines;
    std::ifstream in(path("frames.jsonl"));
    for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
    return lines;
  }
  // The largest difference of two 8-bit images, in display levels.
  static float maxLevelDifference(const io::Image& a, const io::Image& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    float worst = 0.0f;
    for (int y = 0; y < a.height; ++y)
      for (int x = 0; x < a.width; ++x)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.at(x, y, c) - b.at(x, y, c)) * 255.0f);
    return worst;
  }
  VirtualDisplay display_;
};

TEST_F(CliView, ScreenshotEqualsTheHeadlessRenderOfTheSameSettings) {
  const auto shown = view("--spp 4 --frames 4 --no-denoise --no-panel --screenshot " + path("view.png"));
  ASSERT_EQ(shown.exitCode, 0) << shown.output;
  // The window composes with the reached I_a (its camera moves), a still render with the seen one.
  const auto rendered = runObscura("render " + cornellBox() + " --width 48 --height 48 --spp 4 --ambient reached -o " +
                                   path("render.png"));
  ASSERT_EQ(rendered.exitCode, 0) << rendered.output;
  // Same seeds, same samples: the window composes with the light-mix pass, which agrees with the
  // render's compose pass to 2 display levels (LightMix.* tests).
  EXPECT_LE(maxLevelDifference(io::readImage(path("view.png")), io::readImage(path("render.png"))), 2.0f);
}

TEST_F(CliView, DenoisedScreenshotEqualsTheHeadlessDenoisedRender) {
  // The denoiser is on by default in the window; headless it is asked for. The window's history
  // stays while the camera does, so its frame after 4 samples is the headless one's.
  const auto shown = view("--spp 4 --frames 4 --no-panel --screenshot " + path("view.png") + " --log " +
                          path("frames.jsonl"));
  ASSERT_EQ(shown.exitCode, 0) << shown.output;
  const auto denoised = runObscura("render " + cornellBox() + " --width 48 --height 48 --spp 4 --ambient reached "
                                   "--denoise -o " + path("denoised.png"));
  ASSERT_EQ(denoised.exitCode, 0) << denoised.output;
  const auto raw = runObscura("render " + cornellBox() + " --width 48 --height 48 --spp 4 --ambient reached -o " +
                              path("raw.png"));
  ASSERT_EQ(raw.exitCode, 0) << raw.output;
  const io::Image view = io::readImage(path("view.png"));
  EXPECT_LE(maxLevelDifference(view, io::readImage(path("denoised.png"))), 1.0f);
  EXPECT_GT(maxLevelDifference(view, io::readImage(path("raw.png"))), 8.0f) << "the denoiser ran";
  for (const auto& frame : log()) EXPECT_GT(frame["denoise_ms"].get<double>(), 0.0);
}

TEST_F(CliView, DenoisedCameraMoveReprojectsWithoutValidationMessages) {
  writeScript(json::array({{{"frame", 2}, {"drag", {12, 4}}, {"button", "left"}},
                           {{"frame", 3}, {"drag", {12, 4}}, {"button", "left"}}}));
  const auto r = view("--spp 8 --frames 6 --no-panel --script " + path("events.json") + " --log " +
                      path("frames.jsonl") + " --screenshot " + path("moved.png"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto frames = log();
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_TRUE(frames[2]["preview"]);
  EXPECT_TRUE(frames[3]["preview"]);
  for (const auto& frame : frames) EXPECT_GT(frame["denoise_ms"].get<double>(), 0.0);
}

TEST_F(CliView, ScriptedLightEditIsOneComposeThatTracesNothing) {
  // Four samples, then (frame 5) the lamp at twice its power: the frame must be the compose of the
  // same transport with the new emission, which `relight --edits` computes headless.
  writeScript(json::array({{{"frame", 4}, {"screenshot", path("before.exr")}},
                           {{"frame", 5}, {"panel", {{"light", kLight}, {"scale", 2.0}}}}}));
  const auto r = view("--spp 4 --frames 6 --no-denoise --script " + path("events.json") + " --log " +
                      path("frames.jsonl") + " --screenshot " + path("after.exr"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto frames = log();
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_EQ(frames[5]["actions"], json::array({"light_scale"}));
  EXPECT_EQ(frames[5]["rays"], 0) << "a light edit traces no ray";
  EXPECT_EQ(frames[5]["pixels_retraced"], 0);
  EXPECT_EQ(frames[5]["samples"], 4) << "the accumulation goes on";
  EXPECT_FALSE(frames[5]["restarted"]);

  std::ofstream(path("edits.json")) << json::array({{{"light", kLight}, {"scale", 2.0}}}).dump();
  const auto relit = runObscura("relight " + cornellBox() + " --width 48 --height 48 --spp 4 --edits " +
                                path("edits.json") + " -o " + path("relit"));
  ASSERT_EQ(relit.exitCode, 0) << relit.output;
  const io::Image before = io::readImage(path("before.exr"));
  const io::Image after = io::readImage(path("after.exr"));
  const io::Image predicted = io::readImage(path("relit/frame-001.exr"));
  const int a = after.channelIndex("combined.R"), p = predicted.channelIndex("combined.R"),
            b = before.channelIndex("combined.R");
  ASSERT_GE(a, 0);
  ASSERT_GE(p, 0);
  double changed = 0.0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (int c = 0; c < 3; ++c) {
        const float want = predicted.at(x, y, p + c), got = after.at(x, y, a + c);
        EXPECT_NEAR(got, want, 1e-4f * std::max(1.0f, std::abs(want))) << x << "," << y;
        changed += std::abs(got - before.at(x, y, b + c));
      }
  EXPECT_GT(changed / (kSize * kSize * 3), 0.01) << "the edit must show";
}

TEST_F(CliView, CameraMoveRestartsAccumulationWithAPreviewFrame) {
  writeScript(json::array({{{"frame", 3}, {"drag", {30, 10}}, {"button", "left"}}}));
  const auto r = view("--spp 16 --frames 6 --script " + path("events.json") + " --log " + path("frames.jsonl") +
                      " --no-denoise --screenshot " + path("moved.png"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto frames = log();
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_EQ(frames[2]["samples"], 3);
  EXPECT_TRUE(frames[3]["preview"]);
  EXPECT_TRUE(frames[3]["restarted"]);
  EXPECT_EQ(frames[3]["samples"], 1);
  // The preview has one shadow and one obscurance ray per pixel; the frame after starts again with
  // the full rays (5 + 5) and accumulates from there.
  EXPECT_LT(frames[3]["rays"].get<double>(), 0.5 * frames[1]["rays"].get<double>());
  EXPECT_TRUE(frames[4]["restarted"]);
  EXPECT_EQ(frames[4]["samples"], 1);
  EXPECT_EQ(frames[5]["samples"], 2);
  EXPECT_FALSE(frames[5]["restarted"]);

  const auto still = view("--spp 16 --frames 6 --no-denoise --screenshot " + path("still.png"));
  ASSERT_EQ(still.exitCode, 0) << still.output;
  EXPECT_GT(maxLevelDifference(io::readImage(path("moved.png")), io::readImage(path("still.png"))), 40.0f)
      << "the view moved";
}

TEST_F(CliView, ClickedObjectMovedRetracesOnlyItsDirtyPixels) {
  // The short box (cube_1) is at the lower right of the first camera's view; the click selects it,
  // then the panel moves the selection.
  writeScript(json::array({{{"frame", 2}, {"click", {32, 38}}},
                           {{"frame", 3}, {"panel", {{"move", ""}, {"translate", {0.1, 0.0, 0.1}}}}}}));
  const auto r = view("--spp 8 --frames 5 --no-panel --script " + path("events.json") + " --log " +
                      path("frames.jsonl") + " --no-denoise");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto frames = log();
  ASSERT_EQ(frames.size(), 5u);
  EXPECT_EQ(frames[2]["actions"], json::array({"pick"}));
  EXPECT_EQ(frames[3]["actions"], json::array({"move_object"}));
  const auto retraced = frames[3]["pixels_retraced"].get<std::uint64_t>();
  EXPECT_GT(retraced, 0u);
  EXPECT_LT(retraced, std::uint64_t(kSize * kSize)) << "only the pixels the box can change";
  EXPECT_FALSE(frames[3]["restarted"]);
  EXPECT_EQ(frames[3]["samples"], 4) << "retraced pixels catch up with the others";
}

TEST_F(CliView, ClickOnNothingSelectsNothingAndAMoveIsThenRefused) {
  writeScript(json::array({{{"frame", 1}, {"click", {2000, 2000}}},
                           {{"frame", 2}, {"panel", {{"move", ""}, {"translate", {0.1, 0.0, 0.0}}}}}}));
  const auto r = view("--spp 4 --frames 4 --no-panel --script " + path("events.json"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "no object is selected");
}

TEST_F(CliView, ResizeMinimiseRestoreAndCloseMidRunAreClean) {
  writeScript(json::array({{{"frame", 1}, {"window", "resize"}, {"size", {120, 80}}},
                           {{"frame", 2}, {"screenshot", path("resized.png")}},
                           {{"frame", 3}, {"window", "minimize"}},
                           {{"frame", 4}, {"window", "restore"}},
                           {{"frame", 5}, {"window", "close"}}}));
  const auto r = view("--spp 64 --frames 50 --screenshot-ui --script " + path("events.json") + " --log " +
                      path("frames.jsonl"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto frames = log();
  EXPECT_EQ(frames.size(), 6u) << "closed at frame 6's poll";
  const io::Image resized = io::readImage(path("resized.png"));
  EXPECT_EQ(resized.width, 120);
  EXPECT_EQ(resized.height, 80);
}

TEST_F(CliView, PanelShowsInScreenshotsThatAskForIt) {
  const auto plain = view("--spp 2 --frames 2 --no-denoise --screenshot " + path("plain.png"));
  ASSERT_EQ(plain.exitCode, 0) << plain.output;
  const auto withUi = runObscura("view " + cornellBox() + " --width 320 --height 240 --spp 2 --frames 2 --no-denoise " +
                                     "--screenshot-ui --screenshot " + path("ui.png"),
                                 "DISPLAY=" + display_.display() + " ");
  ASSERT_EQ(withUi.exitCode, 0) << withUi.output;
  const io::Image ui = io::readImage(path("ui.png"));
  EXPECT_EQ(ui.width, 320);
  const io::Image image = io::readImage(path("plain.png"));
  EXPECT_EQ(image.width, kSize) << "without the panel, the screenshot is the render";
  // The panel (dark blue-grey, 330 pixels wide at the top left) covers the Cornell box's back wall.
  int panelPixels = 0;
  for (int y = 5; y < 60; ++y)
    for (int x = 5; x < 200; ++x)
      if (ui.at(x, y, 2) > ui.at(x, y, 0) + 0.05f) ++panelPixels;
  EXPECT_GT(panelPixels, 1000);
}

TEST_F(CliView, SavedViewRestoresTheCamera) {
  writeScript(json::array({{{"frame", 1}, {"drag", {25, -15}}, {"button", "left"}},
                           {{"frame", 3}, {"panel", {{"save_view", path("view.json")}}}}}));
  const auto moved = view("--spp 2 --frames 5 --no-denoise --script " + path("events.json") + " --screenshot " +
                          path("moved.png"));
  ASSERT_EQ(moved.exitCode, 0) << moved.output;
  ASSERT_TRUE(fs::exists(path("view.json")));
  const json saved = json::parse(std::ifstream(path("view.json")));
  EXPECT_EQ(saved["type"], "perspective");
  EXPECT_EQ(saved["rotation"].size(), 4u);
  writeScript(json::array({{{"frame", 0}, {"panel", {{"save_view", path("again.json")}}}}}));
  const auto restored = view("--spp 2 --frames 2 --no-denoise --view " + path("view.json") + " --script " +
                             path("events.json") + " --screenshot " + path("restored.png"));
  ASSERT_EQ(restored.exitCode, 0) << restored.output;
  // The view loaded is the view saved (the quaternion's round trip costs a few ulps)...
  const json again = json::parse(std::ifstream(path("again.json")));
  for (const char* key : {"translation", "rotation"})
    for (std::size_t i = 0; i < saved[key].size(); ++i)
      EXPECT_NEAR(again[key][i].get<double>(), saved[key][i].get<double>(), 1e-5) << key << i;
  // ...and so is the image, but for the few edge pixels those ulps move across a triangle edge.
  const io::Image a = io::readImage(path("moved.png")), b = io::readImage(path("restored.png"));
  double mean = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) mean += std::abs(a.pixels[i] - b.pixels[i]) * 255.0;
  EXPECT_LT(mean / double(a.pixels.size()), 0.5);
}

TEST_F(CliView, NoWindowSystemIsAClearErrorAndWritesNothing) {
  const auto r = runObscura("view " + cornellBox() + " --frames 2 --screenshot " + path("shot.png"),
                            "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_EQ(r.exitCode, 3) << r.output;
  EXPECT_CONTAINS(r.output, "no window system");
  EXPECT_TRUE(strayFiles().empty());
}

TEST_F(CliView, BadScriptsAreRefusedBeforeAWindowOpens) {
  const std::vector<std::pair<json, std::string>> cases = {
      {json::object(), "a JSON list"},
      {json::array({{{"key", "W"}}}), "'frame'"},
      {json::array({{{"frame", 1}, {"key", "W"}, {"click", {1, 2}}}}), "exactly one"},
      {json::array({{{"frame", 1}, {"key", "Ctrl+Alt"}}}), "unknown key"},
      {json::array({{{"frame", 1}, {"panel", {{"light", kLight}, {"scale", -1}}}}}), "'scale'"},
      {json::array({{{"frame", 1}, {"window", "resize"}}}), "'size'"},
      {json::array({{{"frame", 1}, {"panel", {{"teleport", 1}}}}}), "unknown panel change"},
  };
  for (const auto& [events, expected] : cases) {
    SCOPED_TRACE(events.dump());
    writeScript(events);
    // No DISPLAY at all: the script is refused before the window system is asked for a window.
    const auto r = runObscura("view " + cornellBox() + " --frames 2 --script " + path("events.json") + " --screenshot " +
                                  path("shot.png"),
                              "env -u DISPLAY ");
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_CONTAINS(r.output, "events.json");
    EXPECT_CONTAINS(r.output, expected);
    EXPECT_FALSE(fs::exists(path("shot.png")));
  }
  // A light the scene does not have is found when the event acts: still exit 2, naming it.
  writeScript(json::array({{{"frame", 1}, {"panel", {{"light", "nope"}, {"scale", 2}}}}}));
  const auto r = view("--frames 3 --script " + path("events.json") + " --screenshot " + path("shot.png"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "no light named 'nope'");
  EXPECT_FALSE(fs::exists(path("shot.png")));
}

} // namespace
} // namespace obscura::test
