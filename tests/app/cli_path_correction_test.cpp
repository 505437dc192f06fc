// `obscura render --pt-correction N`: the corrected frame as the EXR's `corrected` layer and as
// the PNG, with the paths' and the filter's GPU time in the metrics; and what it refuses (path
// tracing, the denoiser beside it, the `corrected` AOV without it), naming the flag, no output.
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
  EXPECT_EQ(strayFiles(), std::vector<std::string>{});
}

} // namespace
} // namespace obscura::test
