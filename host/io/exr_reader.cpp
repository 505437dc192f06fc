#include "io/exr_reader.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <vector>

#include <fmt/core.h>
#include <zlib.h>

#include "core/error.h"

namespace obscura::io {
namespace {

// The compressions and pixel types of the file layout's "compression" and "chlist" attributes.
enum Compression : std::uint8_t { kNone = 0, kRle = 1, kZips = 2, kZip = 3 };
constexpr std::array<const char*, 10> kCompressionNames{"NONE", "RLE",  "ZIPS", "ZIP",  "PIZ",
                                                        "PXR24", "B44", "B44A", "DWAA", "DWAB"};
enum PixelType : std::int32_t { kUint = 0, kHalf = 1, kFloat = 2 };
constexpr std::size_t bytesOf(std::int32_t type) { return type == kHalf ? 2 : 4; }

// The largest image read, in values (width x height x channels): a corrupt header asks for no more.
constexpr std::size_t kMaxValues = std::size_t(1) << 28;

struct Channel {
  std::string name;
  std::int32_t type = kFloat;
  std::size_t output = 0; // its index in the Image
};

// Little-endian reads from the file's bytes (x86-64 and AArch64 Linux are little-endian, as EXR
// is), each checked against the end: a file cut short is an InputError, never a read past it.
class ByteReader {
public:
  ByteReader(const std::vector<unsigned char>& bytes, const std::string& path) : bytes_(bytes), path_(path) {}
  template <typename T> T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string getString() { // up to a 0 byte, which is consumed
    const auto begin = bytes_.begin() + std::ptrdiff_t(at_);
    const auto end = std::find(begin, bytes_.end(), 0);
    if (end == bytes_.end()) fail("a name runs past the end of the file");
    std::string text(begin, end);
    at_ += text.size() + 1;
    return text;
  }
  const unsigned char* take(std::size_t n) {
    need(n);
    const unsigned char* p = bytes_.data() + at_;
    at_ += n;
    return p;
  }
  void seek(std::uint64_t offset) {
    if (offset > bytes_.size()) fail("a scan-line block lies past the end of the file (cut short?)");
    at_ = std::size_t(offset);
  }
  std::size_t position() const { return at_; }
  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(fmt::format("{}: not a readable EXR: {}", path_, problem));
  }

private:
  void need(std::size_t n) const {
    if (n > bytes_.size() - at_) fail("the file ends early (cut short?)");
  }
  const std::vector<unsigned char>& bytes_;
  const std::string& path_;
  std::size_t at_ = 0;
};

// IEEE 754 binary16 to binary32 by its bits: a half's subnormals (m x 2^-24) are normal floats,
// built here without float arithmetic, so a process that flushes denormals reads them as well.
float halfToFloat(std::uint16_t h) {
  const std::uint32_t sign = std::uint32_t(h >> 15) << 31;
  std::uint32_t exponent = (h >> 10) & 0x1Fu, mantissa = h & 0x3FFu, bits;
  if (exponent == 0 && mantissa == 0) {
    bits = sign;
  } else if (exponent == 0) { // subnormal: shift the leading 1 into the implicit bit
    int shifts = 0;
    while (!(mantissa & 0x400u)) mantissa <<= 1, ++shifts;
    bits = sign | std::uint32_t(127 - 14 - shifts) << 23 | (mantissa & 0x3FFu) << 13;
  } else if (exponent == 0x1F) { // infinity or NaN
    bits = sign | 0xFFu << 23 | mantissa << 13;
  } else {
    bits = sign | (exponent - 15 + 127) << 23 | mantissa << 13;
  }
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// RLE's runs (the layout's "RLE compression"): a signed count n, then n + 1 copies of the next
// byte where n >= 0, or -n bytes as they are.
bool runLengthDecode(const unsigned char* in, std::size_t size, std::vector<unsigned char>& out) {
  std::size_t at = 0;
  while (at < size) {
    const int count = static_cast<signed char>(in[at++]);
    if (count < 0) {
      if (std::size_t(-count) > size - at || out.size() + std::size_t(-count) > out.capacity()) return false;
      out.insert(out.end(), in + at, in + at + std::size_t(-count));
      at += std::size_t(-count);
    } else {
      if (at >= size || out.size() + std::size_t(count) + 1 > out.capacity()) return false;
      out.insert(out.end(), std::size_t(count) + 1, in[at++]);
    }
  }
  return true;
}

// What ZIP and RLE undo after their decompression: each byte was stored as its difference from
// the previous one, plus 128, and the block's bytes were split into those at even and those at
// odd positions (the first half of the buffer and the second) to make runs for the compressor.
std::vector<unsigned char> undoPredictorAndSplit(std::vector<unsigned char> split) {
  for (std::size_t i = 1; i < split.size(); ++i) split[i] = static_cast<unsigned char>(split[i - 1] + split[i] - 128);
  std::vector<unsigned char> out(split.size());
  const std::size_t half = (split.size() + 1) / 2;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = split[i % 2 == 0 ? i / 2 : half + i / 2];
  return out;
}

// OpenImageIO's order within a layer: R, G, B, A first, the rest after them.
int standardRank(const std::string& name) {
  const std::size_t dot = name.rfind('.');
  const std::string suffix = dot == std::string::npos ? name : name.substr(dot + 1);
  static const std::array<const char*, 4> kOrder{"R", "G", "B", "A"};
  for (std::size_t i = 0; i < kOrder.size(); ++i)
    if (suffix == kOrder[i]) return int(i);
  return int(kOrder.size());
}

std::string layerOf(const std::string& name) {
  const std::size_t dot = name.rfind('.');
  return dot == std::string::npos ? std::string() : name.substr(0, dot);
}

std::vector<unsigned char> readFile(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(fmt::format("{}: cannot open the file", path));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw InputError(fmt::format("{}: cannot read the file", path));
  return bytes;
}

} // namespace

Image readExr(const std::string& path) {
  const std::vector<unsigned char> bytes = readFile(path);
  ByteReader in(bytes, path);
  if (bytes.size() < 8 || in.get<std::int32_t>() != 20000630) in.fail("it does not start with the EXR magic number");
  const auto version = in.get<std::uint32_t>();
  if ((version & 0xFFu) != 2) in.fail(fmt::format("file format version {}, not 2", version & 0xFFu));
  if (version & 0x200u) in.fail("it is tiled; this build reads scan-line EXR (convert: oiiotool IN --scanline -o OUT)");
  if (version & 0x800u) in.fail("it holds deep data");
  if (version & 0x1000u) in.fail("it has several parts; this build reads single-part EXR");

  // The header: attributes up to an empty name.
  std::vector<Channel> channels;
  std::optional<std::uint8_t> compression;
  std::optional<std::array<std::int32_t, 4>> window; // xMin, yMin, xMax, yMax
  Image image;
  for (std::string name = in.getString(); !name.empty(); name = in.getString()) {
    const std::string type = in.getString();
    const auto size = in.get<std::int32_t>();
    if (size < 0) in.fail(fmt::format("attribute '{}' has a negative size", name));
    const std::size_t end = in.position() + std::size_t(size);
    const unsigned char* value = in.take(std::size_t(size));
    if (name == "channels" && type == "chlist") {
      const std::vector<unsigned char> listBytes(value, value + size);
      ByteReader list(listBytes, path); // keeps a reference: listBytes outlives it
      for (std::string channel = list.getString(); !channel.empty(); channel = list.getString()) {
        Channel c{channel, list.get<std::int32_t>()};
        list.take(4); // pLinear and three reserved bytes
        const auto xSampling = list.get<std::int32_t>(), ySampling = list.get<std::int32_t>();
        if (c.type != kUint && c.type != kHalf && c.type != kFloat)
          in.fail(fmt::format("channel '{}' has pixel type {}", channel, c.type));
        if (xSampling != 1 || ySampling != 1)
          in.fail(fmt::format("channel '{}' is subsampled ({} x {}); this build reads full-resolution channels",
                              channel, xSampling, ySampling));
        channels.push_back(c);
      }
    } else if (name == "compression" && size == 1) {
      compression = value[0];
    } else if (name == "dataWindow" && type == "box2i" && size == 16) {
      window.emplace();
      std::memcpy(window->data(), value, 16);
    } else if (type == "string" && name.rfind("obscura:", 0) == 0) {
      image.attributes.emplace_back(name, std::string(value, value + size));
    }
    in.seek(end);
  }
  if (channels.empty()) in.fail("it has no channels");
  if (!compression || !window) in.fail("its header lacks the compression or the data window");
  if (*compression > kZip) {
    const std::string named = *compression < kCompressionNames.size() ? kCompressionNames[*compression] : "unknown";
    in.fail(fmt::format("{} compression; this build reads NONE, RLE, ZIPS and ZIP (convert: oiiotool IN "
                        "--compression zip -o OUT)", named));
  }
  const auto [xMin, yMin, xMax, yMax] = *window;
  const std::int64_t width = std::int64_t(xMax) - xMin + 1, height = std::int64_t(yMax) - yMin + 1;
  if (width <= 0 || height <= 0 || std::uint64_t(width) * std::uint64_t(height) * channels.size() > kMaxValues)
    in.fail(fmt::format("its data window is {} x {} pixels", width, height));
  image.width = int(width);
  image.height = int(height);

  // The Image's channel order (see exr_reader.h); the file's is the names sorted.
  std::vector<std::size_t> order(channels.size());
  for (std::size_t c = 0; c < order.size(); ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const std::string la = layerOf(channels[a].name), lb = layerOf(channels[b].name);
    if (la != lb) return la < lb; // the unnamed layer, "", first
    return standardRank(channels[a].name) < standardRank(channels[b].name);
  });
  for (std::size_t k = 0; k < order.size(); ++k) {
    channels[order[k]].output = k;
    image.channels.push_back(channels[order[k]].name);
  }
  image.pixels.assign(std::size_t(width) * std::size_t(height) * channels.size(), 0.0f);

  // The offset table, then each block: its first line, its size, its data. A block holds its
  // lines one after another, and in each line every channel's values in the file's order.
  const std::int64_t linesPerBlock = *compression == kZip ? 16 : 1;
  const std::int64_t blocks = (height + linesPerBlock - 1) / linesPerBlock;
  std::size_t pixelBytes = 0;
  for (const Channel& c : channels) pixelBytes += bytesOf(c.type);
  const std::size_t lineBytes = std::size_t(width) * pixelBytes;
  std::vector<std::uint64_t> offsets(static_cast<std::size_t>(blocks));
  for (auto& offset : offsets) offset = in.get<std::uint64_t>();
  std::vector<char> seen(offsets.size(), 0);
  for (const std::uint64_t offset : offsets) {
    in.seek(offset);
    const auto y = in.get<std::int32_t>();
    const auto size = in.get<std::int32_t>();
    const std::int64_t block = (std::int64_t(y) - yMin) / linesPerBlock;
    if (y < yMin || y > yMax || (std::int64_t(y) - yMin) % linesPerBlock != 0 || seen[std::size_t(block)]++)
      in.fail(fmt::format("a block starts at line {}, which is not the start of an unread block", y));
    if (size < 0) in.fail(fmt::format("the block at line {} has a negative size", y));
    const std::int64_t lines = std::min(linesPerBlock, std::int64_t(yMax) - y + 1);
    const std::size_t expected = std::size_t(lines) * lineBytes;
    const unsigned char* data = in.take(std::size_t(size));
    std::vector<unsigned char> raw;
    if (std::size_t(size) == expected) { // stored as it is: what compression did not shrink
      raw.assign(data, data + size);
    } else if (*compression == kNone) {
      in.fail(fmt::format("the block at line {} holds {} bytes, not {}", y, size, expected));
    } else {
      std::vector<unsigned char> split;
      bool ok = false;
      if (*compression == kRle) {
        split.reserve(expected);
        ok = runLengthDecode(data, std::size_t(size), split) && split.size() == expected;
      } else {
        split.resize(expected);
        uLongf length = uLongf(expected);
        ok = uncompress(split.data(), &length, data, uLong(size)) == Z_OK && length == expected;
      }
      if (!ok) in.fail(fmt::format("the {} block at line {} does not decompress to its {} bytes",
                                   kCompressionNames[*compression], y, expected));
      raw = undoPredictorAndSplit(std::move(split));
    }
    const unsigned char* at = raw.data();
    for (std::int64_t line = 0; line < lines; ++line) {
      float* row = image.pixels.data() + std::size_t(y - yMin + line) * std::size_t(width) * channels.size();
      for (const Channel& c : channels)
        for (std::int64_t x = 0; x < width; ++x, at += bytesOf(c.type)) {
          float& v = row[std::size_t(x) * channels.size() + c.output];
          if (c.type == kHalf) {
            std::uint16_t h;
            std::memcpy(&h, at, 2);
            v = halfToFloat(h);
          } else if (c.type == kFloat) {
            std::memcpy(&v, at, 4);
          } else { // OpenImageIO's conversion of an integer to float: u / UINT_MAX, in double
            std::uint32_t u;
            std::memcpy(&u, at, 4);
            v = float(double(u) * (1.0 / double(std::numeric_limits<std::uint32_t>::max())));
          }
        }
    }
  }
  return image;
}

} // namespace obscura::io
