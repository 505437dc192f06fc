// image_error.h — error of an image against a reference [SPEC §4], on linear radiance over the
// three channels of every pixel: RMSE, relMSE = mean(((X - Y) / (Y + 0.01))^2), and two robust
// measures beside them, so that one firefly shows as such instead of hiding in or dominating the
// mean: the mean absolute error, and the RMSE over the 99.9 % of pixels with the smallest error.
// Also the ratio of the mean luminances (a bias in overall brightness).
#pragma once
#include <string>

#include "io/image_io.h"

namespace obscura::analysis {

struct ImageError {
  double rmse = 0.0;
  double relMse = 0.0;
  double mae = 0.0;          // mean |X - Y| over pixels and channels
  double rmseTrimmed = 0.0;  // RMSE without the 0.1 % of pixels with the largest squared error
  double meanRatio = 1.0;    // mean of X / mean of Y over pixels and channels (1 when both are 0)
};

// The fraction of pixels ImageError::rmseTrimmed leaves out.
inline constexpr double kTrimmedFraction = 0.001;

// Compares the three channels starting at `channel` (e.g. "combined.R") of both images. Throws
// std::invalid_argument when sizes differ or a channel is missing.
ImageError imageError(const io::Image& image, const io::Image& reference, const std::string& channel = "combined.R");

} // namespace obscura::analysis
