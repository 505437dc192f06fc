#include "render/scene_data/texture_fit.h"

#include <gtest/gtest.h>

namespace obscura::render {
namespace {

scene::Texture solid(int w, int h, std::uint8_t value, bool srgb) {
  scene::Texture t{.name = std::string("solid"), .width = w, .height = h, .rgba8 = {}, .srgb = srgb};
  t.rgba8.assign(std::size_t(w) * h * 4, value);
  return t;
}

TEST(TextureFit, HalvingAveragesInLinearSpace) {
  // A 2x1 sRGB texture, black and white: the linear mean is 0.5, i.e. sRGB 188, not 128.
  scene::Texture t = solid(2, 1, 0, true);
  for (int c = 0; c < 4; ++c) t.rgba8[4 + c] = 255;
  scene::Texture h = halveTexture(t);
  ASSERT_EQ(h.width, 1);
  ASSERT_EQ(h.height, 1);
  EXPECT_EQ(h.rgba8[0], 188);
  EXPECT_EQ(h.rgba8[3], 128); // alpha is linear
  scene::Texture linear = t;
  linear.srgb = false;
  EXPECT_EQ(halveTexture(linear).rgba8[0], 128);
}

TEST(TextureFit, ReducesTheLargestUntilTheBudgetHolds) {
  std::vector<scene::Texture> textures = {solid(64, 64, 10, false), solid(16, 16, 20, false)};
  std::vector<std::string> notes;
  auto fitted = fitTextures(textures, 8 * 1024, notes); // 16 KiB + 1 KiB > 8 KiB
  std::uint64_t total = 0;
  for (const auto& t : fitted) total += std::uint64_t(t.width) * t.height * 4;
  EXPECT_LE(total, 8u * 1024u);
  EXPECT_EQ(fitted[0].width, 32);
  EXPECT_EQ(fitted[1].width, 16);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("64x64"), std::string::npos);
  EXPECT_EQ(fitted[0].rgba8[0], 10); // a constant stays constant
  notes.clear();
  fitTextures(textures, 1 << 20, notes);
  EXPECT_TRUE(notes.empty());
}

TEST(TextureFit, OddSizesKeepEveryTexel) {
  scene::Texture t = solid(3, 3, 0, false);
  t.rgba8[(2 * 3 + 2) * 4] = 255; // the bottom-right texel
  scene::Texture h = halveTexture(t);
  ASSERT_EQ(h.width, 1);
  EXPECT_EQ(h.rgba8[0], 28); // 255 / 9, folded into the last texel
}

} // namespace
} // namespace obscura::render
