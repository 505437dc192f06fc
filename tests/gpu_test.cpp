#include "gpu_test.h"

#include <algorithm>
#include <cstdlib>

namespace obscura::test {

gpu::Context& testContext() {
  static gpu::Context context(gpu::ContextOptions{.validate = true});
  return context;
}

std::string sharedScene(const std::string& relative) { return std::string(OBSCURA_SHARED_SCENES) + "/" + relative; }
int largestChannelDifference(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
  int worst = 0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(static_cast<int>((a[i] >> (8 * c)) & 255u) - static_cast<int>((b[i] >> (8 * c)) & 255u)));
  return worst;
}

std::string repoPath(const std::string& relative) { return std::string(OBSCURA_SOURCE_DIR) + "/" + relative; }

io::Image channelsOf(const io::Image& all, const std::string& first) {
  io::Image out{.width = all.width, .height = all.height, .channels = {"combined.R", "combined.G", "combined.B"}, .pixels = {}};
  const int c = all.channelIndex(first);
  for (int y = 0; y < all.height; ++y)
    for (int x = 0; x < all.width; ++x)
      for (int k = 0; k < 3; ++k) out.pixels.push_back(all.at(x, y, c + k));
  return out;
}

} // namespace obscura::test
