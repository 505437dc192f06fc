// photo_set_test.cpp — the camera response `recover` assumes: EXR linear as stored, PNG sRGB
// decoded, both times the shot's exposure.
#include "recover/photo_set.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "io/image_io.h"

namespace obscura::recover {
namespace {
namespace fs = std::filesystem;

io::Image ramp() {
  io::Image image;
  image.width = 16;
  image.height = 1;
  image.channels = {"R", "G", "B"};
  for (int x = 0; x < 16; ++x)
    for (int c = 0; c < 3; ++c) image.pixels.push_back(float(x) / 15.0f * (c == 1 ? 0.5f : 1.0f));
  return image;
}

TEST(PhotoSet, SrgbDecodingInvertsTheEncodingCurve) {
  for (float v : {0.0f, 0.002f, 0.0031308f, 0.05f, 0.2f, 0.5f, 1.0f})
    EXPECT_NEAR(srgbToLinear(io::linearToSrgb(v)), v, 1e-5f + 1e-4f * v) << v;
}

TEST(PhotoSet, PngIsSrgbDecodedAndExrIsLinearBothTimesTheExposure) {
  const fs::path dir = fs::temp_directory_path() / fs::path("obscura-photo-set-test");
  fs::create_directories(dir);
  const io::Image image = ramp();
  io::writePng((dir / "ramp.png").string(), image); // encodes with the sRGB curve, 8 bits
  io::writeExr((dir / "ramp.exr").string(), image);
  int w = 0, h = 0;
  const auto png = readRadiance((dir / "ramp.png").string(), 2.0f, w, h);
  const auto exr = readRadiance((dir / "ramp.exr").string(), 2.0f, w, h);
  EXPECT_EQ(w, 16);
  for (int x = 0; x < 16; ++x) {
    const float linear = float(x) / 15.0f;
    EXPECT_FLOAT_EQ(exr[std::size_t(x)].x, 2.0f * linear);
    // 8-bit sRGB: half a level of 255 in the encoded value, at most ~0.7 % of the linear value
    // above 0.05 (the curve's slope), 0.0002 absolute near black.
    EXPECT_NEAR(png[std::size_t(x)].x, 2.0f * linear, 2.0f * (0.0002f + 0.007f * linear)) << x;
    EXPECT_NEAR(png[std::size_t(x)].y, 2.0f * 0.5f * linear, 2.0f * (0.0002f + 0.007f * linear)) << x;
  }
  fs::remove_all(dir);
}

} // namespace
} // namespace obscura::recover
