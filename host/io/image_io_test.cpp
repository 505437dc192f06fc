// PNG is written by stb (with zlib's deflate) and read by stb in every build; OpenImageIO (libpng),
// which other tools stand for, must read the same pixels from it. EXR through OpenImageIO's module.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <vector>
#include <bit>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <fmt/core.h>

#include "core/error.h"
#include "io/image_io.h"
#include "io/exr_writer.h"
#include "io/oiio_codec.h"
#include "io/stb_codec.h"
#include "gpu_test.h"

namespace obscura::io {
namespace {
namespace fs = std::filesystem;

// Pixels whose three channels differ everywhere (an odd size: no row padding hides an off-by-one).
std::vector<std::uint32_t> testPixels(int width, int height) {
  std::vector<std::uint32_t> rgba(std::size_t(width) * height);
  for (std::size_t i = 0; i < rgba.size(); ++i)
    rgba[i] = 0xFF000000u | std::uint32_t((i * 37) & 0xFF) | std::uint32_t((i * 11 + 3) & 0xFF) << 8 |
              std::uint32_t(255 - (i * 5 & 0xFF)) << 16;
  return rgba;
}

void expectPixels(const Image& image, const std::vector<std::uint32_t>& rgba, int width, int height) {
  ASSERT_EQ(image.width, width);
  ASSERT_EQ(image.height, height);
  ASSERT_EQ(image.channels, (std::vector<std::string>{"R", "G", "B"}));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        // 1e-6: OpenImageIO scales by 1/255 rather than dividing; one 8-bit step is 3.9e-3.
        ASSERT_NEAR(image.at(x, y, c), float((rgba[std::size_t(y) * width + x] >> (8 * c)) & 0xFFu) / 255.0f, 1e-6f)
            << "pixel " << x << "," << y << " channel " << c;
}

TEST(ImageIo, PngReadsBackTheSameThroughStbAndOpenImageIo) {
  const int width = 7, height = 5;
  const std::vector<std::uint32_t> rgba = testPixels(width, height);
  const fs::path path = fs::temp_directory_path() / fmt::format("obscura-image-io-{}.png", ::getpid());
  writePngRgba8(path.string(), width, height, rgba);
  const Image viaStb = readImageWithStb(path.string()), viaReader = readImage(path.string());
  expectPixels(viaStb, rgba, width, height);
  expectPixels(viaReader, rgba, width, height);
#ifdef OBSCURA_HAVE_OPENIMAGEIO
  Image viaOpenImageIo;
  EXPECT_EQ(oiioCodec(path.string()).read(path.string(), viaOpenImageIo), "");
  expectPixels(viaOpenImageIo, rgba, width, height);
#endif
  fs::remove(path);
}

TEST(ImageIo, UnreadableImageNamesTheFileThroughStb) {
  const fs::path path = fs::temp_directory_path() / fmt::format("obscura-image-io-{}-bad.png", ::getpid());
  { std::ofstream(path) << "not a png"; }
  try {
    readImageWithStb(path.string());
    fs::remove(path);
    FAIL() << "a text file read as an image";
  } catch (const InputError& e) {
    fs::remove(path);
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

// The writer of builds without OpenImageIO, read back by OpenImageIO (the default build's reader):
// every channel by name, every value bit for bit, names out of order and one longer than 31
// bytes (the long-names flag).
TEST(ImageIo, HalfSubnormalsReadTheSameWhenTheCallerFlushesDenormals) {
#ifndef OBSCURA_HAVE_OPENIMAGEIO
  GTEST_SKIP() << "this build has no OpenImageIO to read the file";
#endif
  // A Cycles photograph (RGB half): its darkest pixels are half subnormals, (57, 56) of shot 1 at
  // 2^-24, 2^-24 and 14 x 2^-24. Read with flush-to-zero and denormals-are-zero on, as a library
  // built with -ffast-math leaves a process, they must not come back as 0; the mode is put back.
  const std::string path = test::repoPath("tests/data/photos/classroom/photo-001.exr");
  const Image plain = readImage(path);
  const unsigned mode = _mm_getcsr();
  _mm_setcsr(mode | _MM_FLUSH_ZERO_MASK | _MM_DENORMALS_ZERO_MASK);
  const Image flushing = readImage(path);
  const unsigned after = _mm_getcsr();
  _mm_setcsr(mode);
  EXPECT_EQ(after, mode | _MM_FLUSH_ZERO_MASK | _MM_DENORMALS_ZERO_MASK);
  EXPECT_EQ(plain.at(57, 56, 0), std::ldexp(1.0f, -24));
  EXPECT_EQ(plain.at(57, 56, 2), std::ldexp(14.0f, -24));
  ASSERT_EQ(flushing.pixels.size(), plain.pixels.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < plain.pixels.size(); ++i)
    differ += std::bit_cast<std::uint32_t>(flushing.pixels[i]) != std::bit_cast<std::uint32_t>(plain.pixels[i]);
  EXPECT_EQ(differ, 0u);
}

TEST(ImageIo, UncompressedExrReadsBackBitForBitThroughOpenImageIo) {
#ifndef OBSCURA_HAVE_OPENIMAGEIO
  GTEST_SKIP() << "this build has no OpenImageIO to read the file back";
#endif
  Image image;
  image.width = 5;
  image.height = 3;
  image.channels = {"R", "G", "B", "albedo.R", "depth.Z", "a.channel.name.longer.than.31.bytes"};
  image.pixels.resize(std::size_t(image.width) * image.height * image.channels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = (i % 3 == 0 ? -1.0f : 1.0f) * std::ldexp(float(i) + 0.1f, int(i % 7) - 3);
  const fs::path path = fs::temp_directory_path() / fmt::format("obscura-image-io-{}.exr", ::getpid());
  writeUncompressedExr(path.string(), path.string(), image);
  const Image back = readImage(path.string());
  fs::remove(path);
  ASSERT_EQ(back.width, image.width);
  ASSERT_EQ(back.height, image.height);
  ASSERT_EQ(back.channelCount(), image.channelCount());
  for (int c = 0; c < image.channelCount(); ++c) {
    const int b = back.channelIndex(image.channels[c]);
    ASSERT_GE(b, 0) << image.channels[c] << " is missing";
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        ASSERT_EQ(back.at(x, y, b), image.at(x, y, c)) << image.channels[c] << " at " << x << "," << y;
  }
}

} // namespace
} // namespace obscura::io
