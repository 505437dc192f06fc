// A render split into a farm's parts (`render --samples A:B --tile I/T`) and merged (`obscura
// merge`), as a user of a cluster runs them: the merged frame is the frame one process renders,
// and what cannot be merged (another job, overlapping or missing parts, bad options) is refused
// naming the file, with nothing written.
//
// Exactness, as host/farm/merge.h states it: a pixel that one part holds (tiles alone) keeps the
// part's float sums, so tiles merge bit for bit into what one part of the whole frame gives.
// Sample ranges split each pixel's Kahan sum, so their merge differs from one process's by float
// rounding only: a relative 1e-6 (a few ulps of a sum over 4 samples; a sample's worth would be
// ~25 % here). The GPU's compose against its C++ twin merge uses: 1e-5 relative, as relight's.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "gpu_test.h"
#include "io/image_io.h"

namespace obscura::test {
namespace {
namespace fs = std::filesystem;

constexpr const char* kSize = " --width 20 --height 14 --spp 4";

class CliFarm : public CliTest {
protected:
  void render(const std::string& args, const std::string& out, const std::string& scene = "") {
    const auto r = runObscura("render " + (scene.empty() ? cornellBox() : scene) + " " + args + " -o " + path(out));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  RunResult merge(const std::string& args) { return runObscura("merge " + args); }
  void mergeOk(const std::string& parts, const std::string& out) {
    std::string list;
    std::istringstream in(parts);
    for (std::string p; in >> p;) list += path(p) + " ";
    const auto r = merge(list + "-o " + path(out));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  // Every channel of `b` in `a`, equal bit for bit.
  static void expectBitIdentical(const io::Image& a, const io::Image& b) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    ASSERT_EQ(a.channels, b.channels);
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
      differing += std::memcmp(&a.pixels[i], &b.pixels[i], sizeof(float)) != 0;
    EXPECT_EQ(differing, 0u) << "of " << a.pixels.size() << " values";
  }
  // Every channel of `reference` present in `image` and within `relative` (of max(1, |v|)).
  static void expectNear(const io::Image& image, const io::Image& reference, float relative) {
    ASSERT_EQ(image.width, reference.width);
    ASSERT_EQ(image.height, reference.height);
    for (int c = 0; c < reference.channelCount(); ++c) {
      const int k = image.channelIndex(reference.channels[c]);
      ASSERT_GE(k, 0) << reference.channels[c];
      float worst = 0.0f;
      for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x) {
          const float want = reference.at(x, y, c), got = image.at(x, y, k);
          if (std::isnan(want) && std::isnan(got)) continue;
          worst = std::max(worst, std::abs(got - want) / std::max(1.0f, std::abs(want)));
        }
      EXPECT_LE(worst, relative) << reference.channels[c];
    }
  }
};

TEST_F(CliFarm, TilesMergeBitIdenticalToTheWholeFrameAndItsRenderAndRelightAsIt) {
  // The tiles in a folder of their own, merged by naming the folder.
  fs::create_directories(path("parts"));
  for (int i = 0; i < 3; ++i)
    render(std::string(kSize) + " --tile " + std::to_string(i) + "/3", "parts/tile" + std::to_string(i) + ".exr");
  render(std::string(kSize) + " --samples 0:4", "whole.exr");
  render(std::string(kSize) + " --save-state " + path("rendered"), "single.exr");
  mergeOk("parts", "tiles.exr");
  mergeOk("whole.exr", "one.exr");
  const io::Image merged = io::readImage(path("tiles.exr")), one = io::readImage(path("one.exr"));
  expectBitIdentical(merged, one);
  // Against `render -o single.exr`: the same channels in the same order; the primary AOVs are
  // resolved by the same code from the same sums (bit-identical), the composed ones by compose's
  // C++ twin.
  const io::Image single = io::readImage(path("single.exr"));
  EXPECT_EQ(merged.channels, single.channels);
  expectNear(merged, single, 1e-5f);
  for (const char* exact : {"albedo.R", "normal.X", "depth.Z", "position.Y", "coverage.A", "primitive.id", "material.id"}) {
    const int a = merged.channelIndex(exact), b = single.channelIndex(exact);
    ASSERT_GE(a, 0);
    for (int y = 0; y < single.height; ++y)
      for (int x = 0; x < single.width; ++x) EXPECT_EQ(merged.at(x, y, a), single.at(x, y, b)) << exact;
  }
  // The merged EXR says which job it is.
  ASSERT_NE(merged.attribute("obscura:job"), nullptr);
  EXPECT_EQ(nlohmann::json::parse(*merged.attribute("obscura:job")).at("spp"), 4);

  // A relighting state merged from the tiles: the render's per-light transport bit for bit, and
  // relit as the render's own state is.
  auto r = merge(path("parts") + " -o " + path("merged"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  expectBitIdentical(io::readImage(path("merged/transport.exr")), io::readImage(path("rendered/transport.exr")));
  const std::string light = "light_rectangle_1";
  for (const char* state : {"merged", "rendered"}) {
    r = runObscura(std::string("relight ") + path(state) + " --light " + light + "=2 -o " + path(std::string(state) + ".exr"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
  }
  expectBitIdentical(io::readImage(path("merged.exr")), io::readImage(path("rendered.exr")));

  // converge takes a path-tracing reference only: this merged frame is of the obscurance method.
  r = runObscura("converge " + cornellBox() + " -o " + path("study") + " --width 20 --pt-reference " + path("tiles.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "tiles.exr: a reference of another image: its method is \"obscurance\"");
}

TEST_F(CliFarm, SampleRangesAndTilesMergeWithinFloatRoundingOnAGlossySceneWithManyLights) {
  // modern-hall: 13 lights, glossy floors (the specular paths' sums S and SA are merged too).
  const std::string scene = sharedScene("modern-hall/modern-hall.gltf");
  const std::string size = " --width 24 --height 16 --spp 4 --max-depth 3";
  render(size + " --samples 0:1", "a.exr", scene);
  render(size + " --samples 1:4 --tile 0/2", "b.exr", scene);
  render(size + " --samples 1:4 --tile 1/2", "c.exr", scene);
  render(size + " --samples 0:4", "whole.exr", scene);
  mergeOk("a.exr b.exr c.exr", "parts.exr");
  mergeOk("whole.exr", "one.exr");
  const io::Image parts = io::readImage(path("parts.exr")), one = io::readImage(path("one.exr"));
  ASSERT_EQ(parts.channels, one.channels);
  EXPECT_GE(one.channelIndex("specular.R"), 0);
  expectNear(parts, one, 1e-6f);
  // Not trivially equal: some light reaches the frame.
  double sum = 0.0;
  for (int y = 0; y < one.height; ++y)
    for (int x = 0; x < one.width; ++x) sum += one.at(x, y, one.channelIndex("combined.G"));
  EXPECT_GT(sum, 0.0);
}

TEST_F(CliFarm, PathTracedPartsMergeIntoTheRender) {
  render(std::string(kSize) + " --method pathtrace --tile 0/2", "t0.exr");
  render(std::string(kSize) + " --method pathtrace --tile 1/2 --samples 0:2", "t1a.exr");
  render(std::string(kSize) + " --method pathtrace --tile 1/2 --samples 2:4", "t1b.exr");
  render(std::string(kSize) + " --method pathtrace", "single.exr");
  mergeOk("t0.exr t1a.exr t1b.exr", "merged.exr");
  const io::Image merged = io::readImage(path("merged.exr")), single = io::readImage(path("single.exr"));
  EXPECT_EQ(merged.channels, single.channels);
  // Tile 0 holds all its samples in one part: bit-identical there; tile 1 within rounding.
  const int c = single.channelIndex("combined.R");
  for (int y = 0; y < single.height; ++y)
    for (int x = 0; x < single.width; ++x)
      for (int k = 0; k < 3; ++k) {
        const float want = single.at(x, y, c + k), got = merged.at(x, y, c + k);
        if (y < single.height / 2) EXPECT_EQ(got, want) << x << "," << y;
        else EXPECT_NEAR(got, want, 1e-6f * std::max(1.0f, std::abs(want))) << x << "," << y;
      }
  // converge takes its path-tracing reference from a merged farm render of its own image only,
  // and says so before rendering anything.
  const std::string converge = "converge " + cornellBox() + " -o " + path("study") + " --pt-reference ";
  auto r = runObscura(converge + path("merged.exr") + " --width 20"); // the study's frame is 20x20
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "merged.exr: a reference of another image: its size is [20,14]");
  r = runObscura(converge + path("t0.exr") + " --width 20");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "t0.exr: not a merged farm render");
  EXPECT_FALSE(fs::exists(path("study/cornell-box.convergence.csv")));
}

TEST_F(CliFarm, MergeRefusesForeignOverlappingAndIncompleteSetsNamingTheFile) {
  render(std::string(kSize) + " --tile 0/3 --samples 0:2", "a.exr");
  render(std::string(kSize) + " --tile 0/3 --samples 2:4", "b.exr");
  render(std::string(kSize) + " --tile 2/3", "c.exr");
  fs::copy_file(path("a.exr"), path("overlap.exr")); // the same part twice
  render(std::string(kSize) + " --tile 1/3 --seed 9", "foreign.exr");
  io::Image plain; // an image, but no part
  plain.width = plain.height = 2;
  plain.channels = {"R", "G", "B"};
  plain.pixels.assign(12, 0.5f);
  io::writeExr(path("plain.exr"), plain);
  const std::vector<std::string> inputs = {"a.exr", "b.exr", "c.exr", "overlap.exr", "foreign.exr", "plain.exr"};
  const std::string complete = path("a.exr") + " " + path("b.exr") + " " + path("c.exr");

  auto r = merge(complete + " -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "tile 1/3 samples 0:4");
  r = merge(complete + " " + path("overlap.exr") + " -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "overlap.exr: overlaps");
  r = merge(complete + " " + path("foreign.exr") + " -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "foreign.exr: a part of another job");
  EXPECT_CONTAINS(r.output, "seed");
  r = merge(path("plain.exr") + " -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "plain.exr: not a part");
  r = merge(path("nothing.exr") + " -o " + path("out.exr"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "nothing.exr");
  EXPECT_TRUE(strayFiles(inputs).empty()) << "a refused merge writes nothing";

  // What is missing, as render options; then a preview that says what it lacks.
  r = merge("--list-missing " + complete);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_CONTAINS(r.output, "--tile 1/3 --samples 0:4");
  r = merge(complete + " --partial -o " + path("preview.png"));
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_CONTAINS(r.output, "PREVIEW");
  EXPECT_CONTAINS(r.output, "tile 1/3 samples 0:4");
  EXPECT_TRUE(fs::exists(path("preview.png")));
  // Rendering the missing part completes the set.
  render(std::string(kSize) + " --tile 1/3 --samples 0:4", "d.exr");
  r = merge(complete + " " + path("d.exr") + " -o " + path("done.png"));
  EXPECT_EQ(r.exitCode, 0) << r.output;
}

TEST_F(CliFarm, BadPartOptionsAreRefusedBeforeAnyWork) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--samples 3:1 -o p.exr", "--samples 3:1"},
      {"--samples 0:9 -o p.exr", "goes past --spp 4"},
      {"--samples x -o p.exr", "expected A:B"},
      {"--tile 3/3 -o p.exr", "--tile 3/3"},
      {"--tile 0/99 -o p.exr", "fewer rows than tiles"},
      {"--tile 0/2 -o p.png", "merge the parts to get a PNG"},
      {"--tile 0/2 --denoise -o p.exr", "--denoise"},
      {"--tile 0/2 --save-state s -o p.exr", "--save-state DIR to 'obscura merge'"},
  };
  for (const auto& [args, expected] : cases) {
    SCOPED_TRACE(args);
    std::string a = args;
    a.replace(a.find("-o ") + 3, std::string::npos, path(a.substr(a.find("-o ") + 3)));
    const auto r = runObscura("render " + cornellBox() + kSize + " " + a);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_CONTAINS(r.output, expected);
  }
  EXPECT_TRUE(strayFiles().empty());
}

} // namespace
} // namespace obscura::test
