// `obscura render --pt-correction auto|N`: the corrected frame as the EXR's `corrected` layer and
// as the PNG, with the paths' and the filter's GPU time in the metrics; the default's paths by
// --spp; and what it refuses (path tracing, the denoiser beside it, the `corrected` AOV without
// it, a word it does not know), naming the flag, with no output.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/cli_runner.h"
#include "io/image_io.h"

namespace obscura::test {
namespace {

class CliPathCorrection : public CliTest {};

TEST_F(CliPathCorrection, WritesTheCorrectedLayerAndPngWithItsTimings) {
  const auto exr = runObscura("render " + cornellBox() + " -o " + path("out.exr") +
                              " --width 24 --spp 2 --pt-correction 2 --metrics " + path("m.json"));
  ASSERT_EQ(exr.exitCode, 0) << exr.output;
  EXPECT_CONTAINS(exr.output, "path-traced correction: 2 paths per pixel");
  const io::Image image = io::readImage(path("out.exr"));
  ASSERT_GE(image.channelIndex("corrected.R"), 0);
  ASSERT_GE(image.channelIndex("combined.R"), 0);
  const auto metrics = nlohmann::json::parse(std::ifstream(path("m.json")));
  EXPECT_EQ(metrics["method"]["path_correction"]["paths"], 2) << metrics.dump(2);
  EXPECT_EQ(metrics["method"]["path_correction"]["filter_iterations"], 4) << metrics.dump(2);
  EXPECT_GT(metrics["passes"]["correction.pathtrace"]["gpu_ms"].get<double>(), 0.0) << metrics.dump(2);
  EXPECT_TRUE(metrics["passes"].contains("correction.filter")) << metrics.dump(2);

  // The PNG shows the corrected frame, not combined: it differs from a PNG of combined alone.
  ASSERT_EQ(runObscura("render " + cornellBox() + " -o " + path("c.png") + " --width 24 --spp 2 --pt-correction 2").exitCode, 0);
  ASSERT_EQ(runObscura("render " + cornellBox() + " -o " + path("o.png") + " --width 24 --spp 2").exitCode, 0);
  std::ifstream a(path("c.png"), std::ios::binary), b(path("o.png"), std::ios::binary);
  const std::string ca((std::istreambuf_iterator<char>(a)), {}), cb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_NE(ca, cb);
}

// The default (auto): none up to the paper's 8 spp, past it one path a further sample, at least 4;
// none with --pt-correction 0, and none where the output shows no combined image.
TEST_F(CliPathCorrection, TheDefaultCorrectsOnlyPastThePapersBudget) {
  auto paths = [&](const std::string& flags) {
    const auto r = runObscura("render " + cornellBox() + " -o " + path("d.exr") + " --width 12 " + flags + " --metrics " +
                              path("d.json"));
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const auto metrics = nlohmann::json::parse(std::ifstream(path("d.json")));
    const auto& c = metrics["method"]["path_correction"];
    const bool layer = io::readImage(path("d.exr")).channelIndex("corrected.R") >= 0;
    EXPECT_EQ(layer, !c.is_null()) << flags;
    return c.is_null() ? 0 : c["paths"].get<int>();
  };
  EXPECT_EQ(paths("--spp 8"), 0);
  EXPECT_EQ(paths("--spp 9"), 4);
  EXPECT_EQ(paths("--spp 16"), 8);
  EXPECT_EQ(paths("--spp 16 --pt-correction 0"), 0);
  EXPECT_EQ(paths("--spp 16 --aov albedo"), 0);
  EXPECT_EQ(paths("--spp 4 --pt-correction 3"), 3);
}

TEST_F(CliPathCorrection, PathTracingAndTheDenoiserAreRefusedWithTheReason) {
  const auto pt = runObscura("render " + cornellBox() + " -o " + path("out.png") +
                             " --width 16 --spp 1 --method pathtrace --pt-correction 2");
  EXPECT_EQ(pt.exitCode, 2) << pt.output;
  EXPECT_CONTAINS(pt.output, "--pt-correction");
  EXPECT_CONTAINS(pt.output, "--method obscurance");
  const auto denoised = runObscura("render " + cornellBox() + " -o " + path("out.png") +
                                   " --width 16 --spp 1 --denoise --pt-correction 2");
  EXPECT_EQ(denoised.exitCode, 2) << denoised.output;
  EXPECT_CONTAINS(denoised.output, "--pt-correction with --denoise");
  const auto aov = runObscura("render " + cornellBox() + " -o " + path("out.exr") + " --width 16 --spp 1 --aov corrected");
  EXPECT_EQ(aov.exitCode, 2) << aov.output;
  EXPECT_CONTAINS(aov.output, "needs --pt-correction");
  const auto word = runObscura("render " + cornellBox() + " -o " + path("out.png") + " --width 16 --pt-correction lots");
  EXPECT_EQ(word.exitCode, 2) << word.output;
  EXPECT_CONTAINS(word.output, "--pt-correction lots: expected auto or a number");
  EXPECT_EQ(strayFiles(), std::vector<std::string>{});
}

} // namespace
} // namespace obscura::test
