#include "analysis/image_error.h"

#include <gtest/gtest.h>

namespace obscura::analysis {
namespace {

io::Image constant(float v) {
  io::Image image;
  image.width = 2;
  image.height = 2;
  image.channels = {"combined.R", "combined.G", "combined.B"};
  image.pixels.assign(12, v);
  return image;
}

TEST(ImageError, RmseAndRelMseFollowTheirDefinitions) {
  ImageError e = imageError(constant(1.5f), constant(1.0f));
  EXPECT_DOUBLE_EQ(e.rmse, 0.5);
  EXPECT_NEAR(e.relMse, (0.5 / 1.01) * (0.5 / 1.01), 1e-12);
  EXPECT_EQ(imageError(constant(1.0f), constant(1.0f)).rmse, 0.0);
  io::Image other = constant(1.0f);
  other.width = 1;
  EXPECT_THROW(imageError(constant(1.0f), other), std::invalid_argument);
}

TEST(ImageError, RobustMeasuresShowOneFireflyAsSuch) {
  // 2000 pixels off by 0.01 and one firefly off by 100: the RMSE is the firefly's, the trimmed
  // RMSE (without the worst 0.1 %, i.e. 2 pixels) and the mean absolute error are the rest's.
  io::Image image, reference;
  for (io::Image* i : {&image, &reference}) {
    i->width = 2001;
    i->height = 1;
    i->channels = {"combined.R", "combined.G", "combined.B"};
    i->pixels.assign(3 * 2001, 1.0f);
  }
  for (std::size_t k = 0; k < 3 * 2000; ++k) image.pixels[k] = 1.01f;
  for (std::size_t k = 3 * 2000; k < 3 * 2001; ++k) image.pixels[k] = 101.0f;
  ImageError e = imageError(image, reference);
  EXPECT_GT(e.rmse, 2.0);
  EXPECT_NEAR(e.rmseTrimmed, 0.01, 1e-6);
  EXPECT_NEAR(e.mae, (2000 * 0.01 + 100.0) / 2001, 1e-6);
  EXPECT_NEAR(e.meanRatio, (2000 * 1.01 + 101.0) / 2001, 1e-6);
  EXPECT_DOUBLE_EQ(imageError(constant(2.0f), constant(1.0f)).meanRatio, 2.0);
}

} // namespace
} // namespace obscura::analysis
