#include "analysis/image_error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace obscura::analysis {

ImageError imageError(const io::Image& image, const io::Image& reference, const std::string& channel) {
  int a = image.channelIndex(channel), b = reference.channelIndex(channel);
  if (a < 0 || b < 0 || a + 2 >= image.channelCount() || b + 2 >= reference.channelCount())
    throw std::invalid_argument("imageError: channel " + channel + " missing");
  if (image.width != reference.width || image.height != reference.height)
    throw std::invalid_argument("imageError: the images differ in size");
  double sq = 0.0, rel = 0.0, absolute = 0.0, sumX = 0.0, sumY = 0.0;
  std::vector<double> pixelSquares; // per pixel, summed over its channels
  pixelSquares.reserve(static_cast<std::size_t>(image.width) * image.height);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      double pixel = 0.0;
      for (int c = 0; c < 3; ++c) {
        double X = image.at(x, y, a + c), Y = reference.at(x, y, b + c);
        double d = X - Y;
        pixel += d * d;
        absolute += std::abs(d);
        double r = d / (Y + 0.01);
        rel += r * r;
        sumX += X;
        sumY += Y;
      }
      sq += pixel;
      pixelSquares.push_back(pixel);
    }
  const double n = 3.0 * image.width * image.height;
  if (n == 0) return {};
  // Keep the ceil((1 - f) n) smallest pixel errors: at least one pixel, all of a tiny image.
  const auto pixels = pixelSquares.size();
  const auto kept = std::max<std::size_t>(
      1, pixels - static_cast<std::size_t>(std::floor(kTrimmedFraction * static_cast<double>(pixels))));
  std::nth_element(pixelSquares.begin(), pixelSquares.begin() + static_cast<std::ptrdiff_t>(kept - 1), pixelSquares.end());
  double trimmed = 0.0;
  for (std::size_t i = 0; i < kept; ++i) trimmed += pixelSquares[i];
  return {.rmse = std::sqrt(sq / n),
          .relMse = rel / n,
          .mae = absolute / n,
          .rmseTrimmed = std::sqrt(trimmed / (3.0 * static_cast<double>(kept))),
          .meanRatio = sumY != 0.0 ? sumX / sumY : (sumX == 0.0 ? 1.0 : HUGE_VAL)};
}

} // namespace obscura::analysis
