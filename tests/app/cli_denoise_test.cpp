// `obscura render --denoise`: the denoised combined image as PNG and as the EXR's `denoised`
// layer, with its GPU time in the metrics; and what it refuses (path tracing keeps no terms to
// denoise; the `denoised` AOV without --denoise), with a message naming the flag and no output.
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

class CliDenoise : public CliTest {};

TEST_F(CliDenoise, WritesTheDenoisedPngAndTheExrLayerWithItsTimings) {
  const auto png = runObscura("render " + cornellBox() + " -o " + path("out.png") + " --width 32 --spp 1 --denoise --metrics " +
                              path("m.json"));
  ASSERT_EQ(png.exitCode, 0) << png.output;
  EXPECT_CONTAINS(png.output, "denoise:");
  EXPECT_TRUE(std::filesystem::exists(path("out.png")));
  const auto metrics = nlohmann::json::parse(std::ifstream(path("m.json")));
  EXPECT_GT(metrics["method"]["denoise"]["gpu_ms"].get<double>(), 0.0) << metrics.dump(2);
  EXPECT_TRUE(metrics["method"]["denoise"]["passes_gpu_ms"].contains("atrous")) << metrics.dump(2);

  const auto exr = runObscura("render " + cornellBox() + " -o " + path("out.exr") + " --width 32 --spp 1 --denoise");
  ASSERT_EQ(exr.exitCode, 0) << exr.output;
  const io::Image image = io::readImage(path("out.exr"));
  EXPECT_GE(image.channelIndex("denoised.R"), 0);
  EXPECT_GE(image.channelIndex("combined.R"), 0);
}

TEST_F(CliDenoise, PathTracingIsRefusedWithTheReason) {
  const auto r = runObscura("render " + cornellBox() + " -o " + path("out.png") + " --width 16 --spp 1 --method pathtrace --denoise");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "--denoise");
  EXPECT_CONTAINS(r.output, "--method obscurance");
  EXPECT_EQ(strayFiles(), std::vector<std::string>{});
}

TEST_F(CliDenoise, TheDenoisedAovNeedsDenoise) {
  const auto r = runObscura("render " + cornellBox() + " -o " + path("out.exr") + " --width 16 --spp 1 --aov denoised");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_CONTAINS(r.output, "--aov denoised");
  EXPECT_CONTAINS(r.output, "needs --denoise");
  EXPECT_EQ(strayFiles(), std::vector<std::string>{});
}

} // namespace
} // namespace obscura::test
