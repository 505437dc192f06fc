// image_io.h — images in and out. PNG is written, and PNG, JPEG, BMP, TGA and HDR are read,
// through stb (io/stb_codec.h); EXR and the other formats through OpenImageIO, in a module loaded
// on first use (io/oiio_codec.h). A build without OpenImageIO (-DOBSCURA_WITH_OPENIMAGEIO=OFF)
// reads scan-line EXR itself (io/exr_reader.h), writes it uncompressed (io/exr_writer.h), and
// reads no other format.
//
// EXR holds linear radiance and every AOV as channel layers ("albedo.R", "depth.Z", …). PNG is
// for viewing only: exposure, then the sRGB curve, 8 bits [SPEC §5]. Files are written to a
// temporary name in the same folder and renamed, so a failed run leaves no partial file.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace obscura::io {

struct Image {
  int width = 0, height = 0;
  std::vector<std::string> channels; // names, e.g. {"R","G","B"} or {"albedo.R", …}
  std::vector<float> pixels;         // interleaved, rows top to bottom
  // Text attributes an EXR carries in its header, named "obscura:..." (a farm's part and a merged
  // frame say which job they belong to, host/farm/). Other formats drop them; readImage reads
  // back only those named "obscura:...".
  std::vector<std::pair<std::string, std::string>> attributes;

  int channelCount() const { return static_cast<int>(channels.size()); }
  float& at(int x, int y, int c) { return pixels[(std::size_t(y) * width + x) * channels.size() + c]; }
  float at(int x, int y, int c) const { return pixels[(std::size_t(y) * width + x) * channels.size() + c]; }
  int channelIndex(const std::string& name) const; // -1 when absent
  // The attribute `name`'s text; nullptr when absent.
  const std::string* attribute(const std::string& name) const;
};

// Writes an EXR (float, all channels). Throws InputError naming the path on failure.
void writeExr(const std::string& path, const Image& image);
// Writes an 8-bit sRGB PNG of channels [first, first + count) after multiplying by 2^exposure;
// count 1 is shown grey (the channel in R, G and B).
void writePng(const std::string& path, const Image& image, int firstChannel = 0, float exposure = 0.0f,
              int count = 3);
// The pixels writePng writes, packed RGBA8 (R in the low byte, alpha 255), as the window shows them.
std::vector<std::uint32_t> encodeRgba8(const Image& image, int firstChannel = 0, float exposure = 0.0f, int count = 3);
// Reads PNG, JPEG, BMP, TGA and HDR through stb, any other image OpenImageIO reads through it
// (linear floats as stored; PNG values / 255, no decoding).
Image readImage(const std::string& path);

// Appends `from`'s channels to `to` (same size; InputError otherwise).
void appendChannels(Image& to, const Image& from);
// Writes an 8-bit PNG of packed RGBA8 pixels (R in the low byte; alpha dropped), as the GPU's
// tonemap pass makes them.
void writePngRgba8(const std::string& path, int width, int height, const std::vector<std::uint32_t>& rgba);
// The sRGB transfer curve (IEC 61966-2-1) of a linear value clamped to [0, 1]: the C++ twin of
// srgbEncode in shaders/tonemap.comp.
float linearToSrgb(float linear);

// The extension, lower case, without the dot ("exr", "png").
std::string extensionOf(const std::string& path);

} // namespace obscura::io
