#include "render/scene_data/texture_fit.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace obscura::render {
namespace {

float toLinear(std::uint8_t v, bool srgb) {
  float c = static_cast<float>(v) / 255.0f;
  if (!srgb) return c;
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

std::uint8_t fromLinear(float c, bool srgb) {
  c = std::clamp(c, 0.0f, 1.0f);
  if (srgb) c = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<std::uint8_t>(std::lround(c * 255.0f));
}

std::uint64_t bytesOf(const scene::Texture& t) { return std::uint64_t(t.width) * std::uint64_t(t.height) * 4u; }

} // namespace

scene::Texture halveTexture(const scene::Texture& in) {
  scene::Texture out;
  out.name = in.name;
  out.srgb = in.srgb;
  out.width = std::max(1, in.width / 2);
  out.height = std::max(1, in.height / 2);
  out.rgba8.resize(bytesOf(out));
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < 4; ++c) {
        // Source footprint: 2x2, widened to 3 on the last row/column of an odd size.
        int x0 = 2 * x, x1 = std::min(in.width, x == out.width - 1 ? in.width : 2 * x + 2);
        int y0 = 2 * y, y1 = std::min(in.height, y == out.height - 1 ? in.height : 2 * y + 2);
        bool linearise = in.srgb && c < 3; // alpha is always linear
        float sum = 0.0f;
        for (int sy = y0; sy < y1; ++sy)
          for (int sx = x0; sx < x1; ++sx)
            sum += toLinear(in.rgba8[(std::size_t(sy) * in.width + sx) * 4 + c], linearise);
        out.rgba8[(std::size_t(y) * out.width + x) * 4 + c] =
            fromLinear(sum / static_cast<float>((x1 - x0) * (y1 - y0)), linearise);
      }
  return out;
}

std::vector<scene::Texture> fitTextures(const std::vector<scene::Texture>& textures, std::uint64_t budgetBytes,
                                        std::vector<std::string>& notes) {
  std::vector<scene::Texture> out = textures;
  std::uint64_t total = 0;
  for (const auto& t : out) total += bytesOf(t);
  std::vector<int> originalWidth, originalHeight;
  for (const auto& t : out) {
    originalWidth.push_back(t.width);
    originalHeight.push_back(t.height);
  }
  while (total > budgetBytes) {
    auto largest = std::max_element(out.begin(), out.end(),
                                    [](const auto& a, const auto& b) { return bytesOf(a) < bytesOf(b); });
    if (largest == out.end() || bytesOf(*largest) <= 4) break; // nothing left to reduce
    total -= bytesOf(*largest);
    *largest = halveTexture(*largest);
    total += bytesOf(*largest);
  }
  for (std::size_t i = 0; i < out.size(); ++i)
    if (out[i].width != originalWidth[i] || out[i].height != originalHeight[i])
      notes.push_back(fmt::format("texture '{}' reduced from {}x{} to {}x{} to fit the device's {} MiB storage "
                                  "buffer limit", out[i].name, originalWidth[i], originalHeight[i], out[i].width,
                                  out[i].height, budgetBytes >> 20));
  return out;
}

} // namespace obscura::render
