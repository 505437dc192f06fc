#include "io/image_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <unistd.h>

#include <fmt/core.h>

#include "core/error.h"
#include "io/exr_reader.h"
#include "io/exr_writer.h"
#include "io/oiio_codec.h"
#include "io/stb_codec.h"

namespace obscura::io {
namespace fs = std::filesystem;

int Image::channelIndex(const std::string& name) const {
  auto it = std::find(channels.begin(), channels.end(), name);
  return it == channels.end() ? -1 : static_cast<int>(it - channels.begin());
}

const std::string* Image::attribute(const std::string& name) const {
  for (const auto& [key, text] : attributes)
    if (key == name) return &text;
  return nullptr;
}

std::string extensionOf(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext;
}

namespace {

// Writes through a temporary file next to the target (same file system, so rename is atomic).
template <typename WriteFn>
void writeAtomically(const std::string& path, WriteFn&& write) {
  fs::path target(path);
  fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  if (!fs::is_directory(dir))
    throw InputError(fmt::format("{}: cannot write: folder '{}' does not exist", path, dir.string()));
  fs::path temp = dir / fmt::format(".{}.tmp{}{}", target.stem().string(), ::getpid(), target.extension().string());
  try {
    write(temp.string());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(temp, target, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw InputError(fmt::format("{}: cannot write: {}", path, ec.message()));
  }
}

// The formats stb reads (io/stb_codec.h) in every build, without loading OpenImageIO.
bool stbReads(const std::string& path) {
  const std::string ext = extensionOf(path);
  return ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "bmp" || ext == "tga" || ext == "hdr";
}

} // namespace

float linearToSrgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

void appendChannels(Image& to, const Image& from) {
  if (to.width != from.width || to.height != from.height)
    throw InputError(fmt::format("cannot add {}x{} channels to a {}x{} image", from.width, from.height, to.width,
                                 to.height));
  const std::size_t a = to.channels.size(), b = from.channels.size(), n = std::size_t(to.width) * to.height;
  std::vector<float> pixels(n * (a + b));
  for (std::size_t p = 0; p < n; ++p) {
    std::copy_n(&to.pixels[p * a], a, &pixels[p * (a + b)]);
    std::copy_n(&from.pixels[p * b], b, &pixels[p * (a + b) + a]);
  }
  to.pixels = std::move(pixels);
  to.channels.insert(to.channels.end(), from.channels.begin(), from.channels.end());
}

void writePngRgba8(const std::string& path, int width, int height, const std::vector<std::uint32_t>& rgba) {
  std::vector<unsigned char> rgb(std::size_t(width) * height * 3);
  for (std::size_t i = 0; i < rgb.size() / 3; ++i)
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = static_cast<unsigned char>((rgba[i] >> (8 * c)) & 0xFFu);
  writeAtomically(path, [&](const std::string& temp) { writePngWithStb(temp, path, width, height, 3, rgb.data()); });
}

void writeExr(const std::string& path, const Image& image) {
#ifndef OBSCURA_HAVE_OPENIMAGEIO
  writeAtomically(path, [&](const std::string& temp) { writeUncompressedExr(temp, path, image); });
#else
  const OiioCodec& codec = oiioCodec(path);
  writeAtomically(path, [&](const std::string& temp) {
    if (std::string failure = codec.writeFloat(temp, image); !failure.empty())
      throw InputError(fmt::format("{}: {}", path, failure));
  });
#endif
}

std::vector<std::uint32_t> encodeRgba8(const Image& image, int firstChannel, float exposure, int count) {
  const float scale = std::exp2(exposure);
  std::vector<std::uint32_t> rgba(std::size_t(image.width) * image.height, 0xFF000000u);
  const int n = image.channelCount();
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        int source = std::min(firstChannel + (count == 1 ? 0 : c), n - 1);
        float v = image.at(x, y, source) * scale;
        if (!std::isfinite(v)) v = 0.0f;
        rgba[std::size_t(y) * image.width + x] |= std::uint32_t(std::lround(linearToSrgb(v) * 255.0f)) << (8 * c);
      }
  return rgba;
}

void writePng(const std::string& path, const Image& image, int firstChannel, float exposure, int count) {
  writePngRgba8(path, image.width, image.height, encodeRgba8(image, firstChannel, exposure, count));
}

Image readImage(const std::string& path) {
  if (stbReads(path)) return readImageWithStb(path);
#ifndef OBSCURA_HAVE_OPENIMAGEIO
  if (extensionOf(path) == "exr") return readExr(path);
  throw InputError(fmt::format("{}: cannot read .{} images: this build has no OpenImageIO (it reads EXR, PNG, JPEG, "
                               "BMP, TGA and HDR)", path, extensionOf(path)));
#else
  Image image;
  if (std::string failure = oiioCodec(path).read(path, image); !failure.empty())
    throw InputError(fmt::format("{}: {}", path, failure));
  return image;
#endif
}

} // namespace obscura::io
