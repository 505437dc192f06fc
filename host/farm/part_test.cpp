#include "farm/part.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"

namespace obscura::farm {
namespace {

TEST(FarmPart, TilesAreBalancedStripsThatCoverEveryRowOnce) {
  for (std::uint32_t height : {1u, 7u, 30u, 1080u})
    for (std::uint32_t count = 1; count <= std::min(height, 17u); ++count) {
      std::uint32_t next = 0, smallest = height, largest = 0;
      for (std::uint32_t i = 0; i < count; ++i) {
        const render::RowRange rows = tileRows({i, count}, height);
        EXPECT_EQ(rows.first, next) << height << " rows, tile " << i << "/" << count;
        next = rows.first + rows.count;
        smallest = std::min(smallest, rows.count);
        largest = std::max(largest, rows.count);
      }
      EXPECT_EQ(next, height);
      EXPECT_GE(smallest, 1u);
      EXPECT_LE(largest - smallest, 1u);
    }
  EXPECT_THROW(tileRows({0, 31}, 30), InputError);
}

TEST(FarmPart, RangesAndTilesParseOrSayWhatIsExpected) {
  EXPECT_EQ(parseSampleRange("0:64"), (SampleRange{0, 64}));
  EXPECT_EQ(parseSampleRange("17:18"), (SampleRange{17, 18}));
  EXPECT_EQ(parseTile("3/16"), (Tile{3, 16}));
  for (const char* bad : {"", "5", "4:4", "5:4", "-1:3", "1:2:3", "a:b", "1:", " 1:2"})
    EXPECT_THROW(parseSampleRange(bad), InputError) << bad;
  for (const char* bad : {"", "3", "3/3", "0/0", "1/-2", "x/2", "1/2/3"}) EXPECT_THROW(parseTile(bad), InputError) << bad;
  EXPECT_TRUE((SampleRange{0, 4}).overlaps({3, 8}));
  EXPECT_FALSE((SampleRange{0, 4}).overlaps({4, 8}));
}

TEST(FarmPart, FrameLayoutOfATileKeepsImageRowsInItsBands) {
  // A tile's bands are numbered in image rows (what the shaders see), its pixels from 0.
  const render::FrameLayout layout = render::FrameLayout::split(10, 100, 1000, 25000, "test", {.first = 40, .count = 7});
  EXPECT_EQ(layout.height, 7u);
  EXPECT_EQ(layout.imageHeight, 100u);
  ASSERT_EQ(layout.bandCount(), 4u); // 2 rows of 10 pixels of 1000 bytes a band
  EXPECT_EQ(layout.bands[0].firstRow, 40u);
  EXPECT_EQ(layout.bands[3].firstRow, 46u);
  EXPECT_EQ(layout.bands[3].rows, 1u);
  EXPECT_EQ(layout.bandFirstPixel(3), 60u);
  EXPECT_THROW(render::FrameLayout::split(10, 100, 4, 1 << 20, "test", {.first = 95, .count = 6}), InputError);
}

TEST(FarmPart, SceneHashFollowsTheFilesAGltfNames) {
  const auto dir = std::filesystem::temp_directory_path() / "obscura_scene_hash_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; };
  write("s.gltf", R"({"asset":{"version":"2.0"},"buffers":[{"uri":"my%20data.bin","byteLength":4}]})");
  write("my data.bin", "abcd");
  const std::string scene = (dir / "s.gltf").string();
  const std::string before = sceneHash(scene);
  EXPECT_EQ(before.size(), 64u);
  EXPECT_EQ(sceneHash(scene), before);
  write("my data.bin", "abce"); // the geometry changed, the .gltf did not
  EXPECT_NE(sceneHash(scene), before);
  std::filesystem::remove(dir / "my data.bin");
  EXPECT_THROW(sceneHash(scene), InputError);
  std::filesystem::remove_all(dir);
}

} // namespace
} // namespace obscura::farm
