#include "analysis/image_error.h"

#include <cmath>
#include <stdexcept>

namespace obscura::render {

ImageError imageError(const io::Image& image, const io::Image& reference, const std::string& channel) {
  int a = image.channelIndex(channel), b = reference.channelIndex(channel);
  if (a < 0 || b < 0 || a + 2 >= image.channelCount() || b + 2 >= reference.channelCount())
    throw std::invalid_argument("imageError: channel " + channel + " missing");
  if (image.width != reference.width || image.height != reference.height)
    throw std::invalid_argument("imageError: the images differ in size");
  double sq = 0.0, rel = 0.0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        double X = image.at(x, y, a + c), Y = reference.at(x, y, b + c);
        double d = X - Y;
        sq += d * d;
        double r = d / (Y + 0.01);
        rel += r * r;
      }
  const double n = 3.0 * image.width * image.height;
  return {.rmse = n > 0 ? std::sqrt(sq / n) : 0.0, .relMse = n > 0 ? rel / n : 0.0};
}

} // namespace obscura::render
