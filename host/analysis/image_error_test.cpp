#include "analysis/image_error.h"

#include <gtest/gtest.h>

namespace obscura::render {
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

} // namespace
} // namespace obscura::render
