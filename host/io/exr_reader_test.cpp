// The native EXR reader (builds without OpenImageIO) against OpenImageIO, the default build's
// reader: the same channels in the same order, every value bit for bit, on Cycles' photographs,
// on what both EXR writers write, and on tests/data/exr (tools/make_exr_samples.py: every
// compression it reads, HALF/FLOAT/UINT, four layers named out of order). What it does not read
// is refused with an error that names the file.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <pmmintrin.h>
#include <string>
#include <unistd.h>
#include <vector>
#include <xmmintrin.h>

#include <fmt/core.h>

#include "core/error.h"
#include "gpu_test.h"
#include "io/exr_reader.h"
#include "io/exr_writer.h"
#include "io/image_io.h"
#include "io/oiio_codec.h"

namespace obscura::io {
namespace {
namespace fs = std::filesystem;

// Bit for bit: a NaN equals the same NaN, and -0 is not +0.
void expectSameImage(const Image& native, const Image& reference, const std::string& what) {
  ASSERT_EQ(native.width, reference.width) << what;
  ASSERT_EQ(native.height, reference.height) << what;
  ASSERT_EQ(native.channels, reference.channels) << what;
  ASSERT_EQ(native.pixels.size(), reference.pixels.size()) << what;
  std::size_t differ = 0, first = 0;
  for (std::size_t i = 0; i < native.pixels.size(); ++i)
    if (std::bit_cast<std::uint32_t>(native.pixels[i]) != std::bit_cast<std::uint32_t>(reference.pixels[i]))
      if (differ++ == 0) first = i;
  EXPECT_EQ(differ, 0u) << what << ": first at value " << first << ", " << native.pixels[first] << " against "
                        << reference.pixels[first];
}

std::string testFile(const std::string& name) {
  return (fs::temp_directory_path() / fmt::format("obscura-exr-reader-{}-{}", ::getpid(), name)).string();
}

#ifdef OBSCURA_HAVE_OPENIMAGEIO
Image readWithOpenImageIo(const std::string& path) {
  Image image;
  const std::string failure = oiioCodec(path).read(path, image);
  EXPECT_EQ(failure, "") << path;
  return image;
}
#endif

// The error names the file and says what the matter is.
void expectRefused(const std::string& path, const std::string& problem) {
  try {
    readExr(path);
    FAIL() << path << " was read";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
  }
}

TEST(ExrReader, ReadsEveryCompressionAndPixelTypeAsOpenImageIoDoes) {
#ifndef OBSCURA_HAVE_OPENIMAGEIO
  GTEST_SKIP() << "this build has no OpenImageIO to compare with";
#else
  const Image none = readExr(test::repoPath("tests/data/exr/samples-none.exr"));
  // OpenImageIO's order: the unnamed layer first with R, G, B, A before the rest, then the layers.
  EXPECT_EQ(none.channels, (std::vector<std::string>{"R", "G", "B", "A", "id", "depth.Z", "diffuse.R", "diffuse.G",
                                                      "diffuse.B"}));
  ASSERT_NE(none.attribute("obscura:part"), nullptr);
  EXPECT_EQ(*none.attribute("obscura:part"), "2 of 5");
  EXPECT_TRUE(std::isinf(none.at(7, 5, 0)));
  for (const char* compression : {"none", "rle", "zips", "zip"}) {
    const std::string path = test::repoPath(fmt::format("tests/data/exr/samples-{}.exr", compression));
    const Image native = readExr(path);
    expectSameImage(native, readWithOpenImageIo(path), path);
    expectSameImage(native, none, path + " against samples-none.exr");
    EXPECT_EQ(native.attributes, none.attributes) << path;
  }
#endif
}

TEST(ExrReader, ReadsCyclesPhotographsAndTheirPassesAsOpenImageIoDoes) {
#ifndef OBSCURA_HAVE_OPENIMAGEIO
  GTEST_SKIP() << "this build has no OpenImageIO to compare with";
#else
  // A photograph (RGB half, ZIP) and an answer key with Cycles' passes as layers.
  for (const char* file : {"tests/data/photos/classroom/photo-001.exr", "tests/data/photos/wooden-staircase/albedo.exr",
                           "tests/data/cornell-new-lamp.exr"}) {
    const std::string path = test::repoPath(file);
    expectSameImage(readExr(path), readWithOpenImageIo(path), path);
  }
#endif
}

// A half's subnormals are built from its bits, so a caller that flushes denormals (a library
// built with -ffast-math) still reads the darkest pixels: (57, 56) of the classroom's shot 1 is
// 2^-24, 2^-24, 14 x 2^-24.
TEST(ExrReader, HalfSubnormalsReadTheSameWhenTheCallerFlushesDenormals) {
  const std::string path = test::repoPath("tests/data/photos/classroom/photo-001.exr");
  const Image plain = readExr(path);
  const unsigned mode = _mm_getcsr();
  _mm_setcsr(mode | _MM_FLUSH_ZERO_MASK | _MM_DENORMALS_ZERO_MASK);
  const Image flushing = readExr(path);
  _mm_setcsr(mode);
  EXPECT_EQ(plain.at(57, 56, 0), std::ldexp(1.0f, -24));
  EXPECT_EQ(plain.at(57, 56, 2), std::ldexp(14.0f, -24));
  expectSameImage(flushing, plain, path + " read flushing denormals");
}

// What render, relight and converge write, in both builds: OpenImageIO's float ZIP (writeExr in
// this build) and exr_writer.h's uncompressed float, with a farm part's attribute and a name
// longer than 31 bytes. Read back by name, bit for bit, in OpenImageIO's order.
TEST(ExrReader, ReadsBothWritersOutputBitForBit) {
  Image image;
  image.width = 6;
  image.height = 35; // ZIP's third block is 3 lines
  image.channels = {"R", "G", "B", "albedo.R", "depth.Z", "a.channel.name.longer.than.31.bytes"};
  image.attributes = {{"obscura:part", "1 of 3"}, {"obscura:job", "cornell"}};
  image.pixels.resize(std::size_t(image.width) * image.height * image.channels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = (i % 3 == 0 ? -1.0f : 1.0f) * std::ldexp(float(i) + 0.1f, int(i % 61) - 30);
  const std::string compressed = testFile("written.exr"), uncompressed = testFile("uncompressed.exr");
  writeExr(compressed, image);
  writeUncompressedExr(uncompressed, uncompressed, image);
  for (const std::string& path : {compressed, uncompressed}) {
    const Image back = readExr(path);
    ASSERT_EQ(back.width, image.width) << path;
    ASSERT_EQ(back.height, image.height) << path;
    ASSERT_EQ(back.channelCount(), image.channelCount()) << path;
    for (const auto& [name, text] : image.attributes) {
      ASSERT_NE(back.attribute(name), nullptr) << path << " lacks " << name;
      EXPECT_EQ(*back.attribute(name), text) << path;
    }
    for (int c = 0; c < image.channelCount(); ++c) {
      const int b = back.channelIndex(image.channels[c]);
      ASSERT_GE(b, 0) << path << " lacks " << image.channels[c];
      for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
          ASSERT_EQ(std::bit_cast<std::uint32_t>(back.at(x, y, b)), std::bit_cast<std::uint32_t>(image.at(x, y, c)))
              << path << ": " << image.channels[c] << " at " << x << "," << y;
    }
#ifdef OBSCURA_HAVE_OPENIMAGEIO
    expectSameImage(back, readWithOpenImageIo(path), path);
#endif
  }
  fs::remove(compressed);
  fs::remove(uncompressed);
}

TEST(ExrReader, RefusesWhatItDoesNotReadNamingTheFile) {
  expectRefused(test::repoPath("tests/data/exr/samples-piz.exr"), "PIZ compression");
  expectRefused(test::repoPath("tests/data/exr/samples-tiled.exr"), "tiled");
  expectRefused(testFile("missing.exr"), "cannot open");

  const std::string notExr = testFile("not.exr");
  { std::ofstream(notExr) << "P6 not an EXR at all"; }
  expectRefused(notExr, "magic number");

  // Cut short in the header, in the offset table and in the last block.
  std::ifstream source(test::repoPath("tests/data/exr/samples-zip.exr"), std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(source)), std::istreambuf_iterator<char>());
  const std::string cut = testFile("cut.exr");
  for (const std::size_t length : {std::size_t(40), std::size_t(530), bytes.size() - 100}) {
    { std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(length)); }
    expectRefused(cut, "not a readable EXR");
  }
  // A corrupt block: the first block's compressed bytes overwritten (its first 4 lines are 0, so
  // it is stored compressed; it starts after the header's 520 bytes, the 3 offsets and its own 8).
  std::vector<char> corrupt = bytes;
  for (std::size_t i = 600; i < 700; ++i) corrupt[i] = char(i * 7);
  { std::ofstream(cut, std::ios::binary).write(corrupt.data(), std::streamsize(corrupt.size())); }
  expectRefused(cut, "does not decompress");
  fs::remove(notExr);
  fs::remove(cut);
}

// readImage takes .exr to this reader where OpenImageIO is not built in.
TEST(ExrReader, ReadImageReadsExrInEveryBuild) {
  const std::string path = test::repoPath("tests/data/exr/samples-zips.exr");
  expectSameImage(readImage(path), readExr(path), path);
}

} // namespace
} // namespace obscura::io
