#include "io/exr_writer.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <numeric>
#include <set>
#include <vector>

#include <fmt/core.h>

#include "core/error.h"

namespace obscura::io {
namespace {

// Little-endian bytes of the file, in the order the OpenEXR file layout gives them
// (openexr.com, "OpenEXR File Layout": magic number, version field, header, offset table, chunks).
class ByteWriter {
public:
  template <typename T> void put(T value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T)); // x86-64 and AArch64 Linux are little-endian, as EXR is
    bytes_.insert(bytes_.end(), bytes, bytes + sizeof(T));
  }
  void putString(const std::string& text) { bytes_.insert(bytes_.end(), text.begin(), text.end()), bytes_.push_back(0); }
  // An attribute: name, type name, size in bytes, value (written by `value`).
  template <typename WriteValue> void attribute(const std::string& name, const std::string& type, WriteValue&& value) {
    putString(name);
    putString(type);
    const std::size_t sizeAt = bytes_.size();
    put<std::int32_t>(0);
    const std::size_t start = bytes_.size();
    value();
    const auto size = static_cast<std::int32_t>(bytes_.size() - start);
    std::memcpy(&bytes_[sizeAt], &size, sizeof size);
  }
  const std::vector<unsigned char>& bytes() const { return bytes_; }
  std::size_t size() const { return bytes_.size(); }

private:
  std::vector<unsigned char> bytes_;
};

} // namespace

void writeUncompressedExr(const std::string& path, const std::string& shownPath, const Image& image) {
  const int n = image.channelCount();
  if (image.width <= 0 || image.height <= 0 || n == 0 ||
      image.pixels.size() != std::size_t(image.width) * image.height * n)
    throw InputError(fmt::format("{}: cannot write a {}x{} EXR of {} channels", shownPath, image.width, image.height, n));
  if (std::set<std::string>(image.channels.begin(), image.channels.end()).size() != image.channels.size())
    throw InputError(fmt::format("{}: cannot write an EXR with two channels of the same name", shownPath));
  // The channel list, and each scan line's data, go in the order of the names' bytes.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return image.channels[a] < image.channels[b]; });
  bool longNames = false;
  for (const std::string& name : image.channels) longNames |= name.size() > 31;

  ByteWriter out;
  out.put<std::int32_t>(20000630); // magic number
  out.put<std::int32_t>(2 | (longNames ? 0x400 : 0)); // version 2, single-part scan lines
  out.attribute("channels", "chlist", [&] {
    for (int c : order) {
      out.putString(image.channels[c]);
      out.put<std::int32_t>(2); // FLOAT
      out.put<std::uint8_t>(0), out.put<std::uint8_t>(0), out.put<std::uint8_t>(0), out.put<std::uint8_t>(0);
      out.put<std::int32_t>(1), out.put<std::int32_t>(1); // x and y sampling
    }
    out.put<std::uint8_t>(0);
  });
  out.attribute("compression", "compression", [&] { out.put<std::uint8_t>(0); }); // NO_COMPRESSION
  const auto window = [&] {
    out.put<std::int32_t>(0), out.put<std::int32_t>(0);
    out.put<std::int32_t>(image.width - 1), out.put<std::int32_t>(image.height - 1);
  };
  out.attribute("dataWindow", "box2i", window);
  out.attribute("displayWindow", "box2i", window);
  out.attribute("lineOrder", "lineOrder", [&] { out.put<std::uint8_t>(0); }); // INCREASING_Y
  out.attribute("pixelAspectRatio", "float", [&] { out.put<float>(1.0f); });
  out.attribute("screenWindowCenter", "v2f", [&] { out.put<float>(0.0f), out.put<float>(0.0f); });
  out.attribute("screenWindowWidth", "float", [&] { out.put<float>(1.0f); });
  for (const auto& [name, text] : image.attributes) // "string": the bytes, no terminator
    out.attribute(name, "string", [&] { for (char c : text) out.put<char>(c); });
  out.put<std::uint8_t>(0); // end of header

  // Offset table: one chunk per scan line without compression. The chunks stream to the file one
  // line at a time, so a large image is not held twice.
  const std::size_t lineBytes = std::size_t(image.width) * n * sizeof(float);
  const std::size_t firstChunk = out.size() + std::size_t(image.height) * sizeof(std::uint64_t);
  for (int y = 0; y < image.height; ++y)
    out.put<std::uint64_t>(firstChunk + std::size_t(y) * (2 * sizeof(std::int32_t) + lineBytes));
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(out.bytes().data()), static_cast<std::streamsize>(out.size()));
  std::vector<float> line(std::size_t(image.width) * n);
  for (int y = 0; y < image.height && file; ++y) {
    const std::int32_t chunkHeader[2] = {y, static_cast<std::int32_t>(lineBytes)};
    file.write(reinterpret_cast<const char*>(chunkHeader), sizeof chunkHeader);
    for (int k = 0; k < n; ++k)
      for (int x = 0; x < image.width; ++x) line[std::size_t(k) * image.width + x] = image.at(x, y, order[k]);
    file.write(reinterpret_cast<const char*>(line.data()), static_cast<std::streamsize>(lineBytes));
  }
  if (!file.flush()) throw InputError(fmt::format("{}: cannot write the EXR", shownPath));
}

} // namespace obscura::io
