#include "io/stb_codec.h"

#include <algorithm>
#include <cstdint>
#include <memory>

#include <cstdlib>

#include <fmt/core.h>
#include <zlib.h>

#include "core/error.h"

namespace {

// stb's PNG writer with zlib's deflate instead of its own (STBIW_ZLIB_COMPRESS): a third smaller
// (the Cornell box at 512x512: 261 KB, where stb's own made 396 KB and libpng 269 KB). stb frees the
// result with free(). `level` is stbi_write_png_compression_level (8).
unsigned char* deflateWithZlib(unsigned char* data, int length, int* outLength, int level) {
  uLongf size = compressBound(static_cast<uLong>(length));
  auto* out = static_cast<unsigned char*>(std::malloc(size));
  if (out == nullptr) return nullptr;
  if (compress2(out, &size, data, static_cast<uLong>(length), level) != Z_OK) {
    std::free(out);
    return nullptr;
  }
  *outLength = static_cast<int>(size);
  return out;
}

} // namespace

#define STBIW_ZLIB_COMPRESS deflateWithZlib

// stb's implementations, static so that they cannot clash with the copy of stb_image that the
// glTF loader compiles for textures. Under /usr/include they are system headers, whose warnings
// the compiler keeps to itself.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace obscura::io {

void writePngWithStb(const std::string& path, const std::string& shownPath, int width, int height, int channels,
                     const unsigned char* pixels) {
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4)
    throw InputError(fmt::format("{}: cannot write a {}x{} PNG of {} channels", shownPath, width, height, channels));
  if (!stbi_write_png(path.c_str(), width, height, channels, pixels, width * channels))
    throw InputError(fmt::format("{}: cannot write the PNG", shownPath));
}

Image readImageWithStb(const std::string& path) {
  int width = 0, height = 0, channels = 0;
  if (!stbi_info(path.c_str(), &width, &height, &channels))
    throw InputError(fmt::format("{}: cannot read image: {}", path, stbi_failure_reason()));
  Image image;
  image.width = width;
  image.height = height;
  static const char* const kNames[4][4] = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  image.channels.assign(kNames[channels - 1], kNames[channels - 1] + channels);
  const std::size_t values = std::size_t(width) * height * channels;
  image.pixels.resize(values);
  int w = 0, h = 0, n = 0;
  auto fail = [&] { return InputError(fmt::format("{}: cannot read image: {}", path, stbi_failure_reason())); };
  if (stbi_is_hdr(path.c_str())) {
    std::unique_ptr<float, void (*)(void*)> data(stbi_loadf(path.c_str(), &w, &h, &n, channels), stbi_image_free);
    if (!data) throw fail();
    std::copy_n(data.get(), values, image.pixels.begin());
  } else if (stbi_is_16_bit(path.c_str())) {
    std::unique_ptr<std::uint16_t, void (*)(void*)> data(stbi_load_16(path.c_str(), &w, &h, &n, channels),
                                                         stbi_image_free);
    if (!data) throw fail();
    for (std::size_t i = 0; i < values; ++i) image.pixels[i] = float(data.get()[i]) / 65535.0f;
  } else {
    std::unique_ptr<unsigned char, void (*)(void*)> data(stbi_load(path.c_str(), &w, &h, &n, channels),
                                                         stbi_image_free);
    if (!data) throw fail();
    for (std::size_t i = 0; i < values; ++i) image.pixels[i] = float(data.get()[i]) / 255.0f;
  }
  return image;
}

} // namespace obscura::io
