// image_error.h — error of an image against a reference [SPEC §4], on linear radiance, per pixel
// over all channels: RMSE and relMSE = mean(((X - Y) / (Y + 0.01))^2).
#pragma once
#include <string>

#include "io/image_io.h"

namespace obscura::render {

struct ImageError {
  double rmse = 0.0;
  double relMse = 0.0;
};

// Compares the three channels starting at `channel` (e.g. "combined.R") of both images. Throws
// std::invalid_argument when sizes differ or a channel is missing.
ImageError imageError(const io::Image& image, const io::Image& reference, const std::string& channel = "combined.R");

} // namespace obscura::render
