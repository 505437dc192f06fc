// stb_codec.h — images through stb (stb_image_write, stb_image), which every build has.
//
// Every build writes PNG and reads PNG, JPEG, BMP, TGA and HDR through here, without loading
// OpenImageIO (io/oiio_codec.h says why); a build without OpenImageIO (a machine lent for GPU
// benchmarks, where its ~400 MB of dependencies cannot travel) has nothing else.
#pragma once
#include <string>

#include "io/image_io.h"

namespace obscura::io {

// Writes `channels` (1-4) interleaved 8-bit values per pixel, rows top to bottom, as a PNG at
// `path`. Throws InputError naming `shownPath` (the name the user gave; `path` may be a
// temporary file beside it).
void writePngWithStb(const std::string& path, const std::string& shownPath, int width, int height, int channels,
                     const unsigned char* pixels);

// Reads a PNG, JPEG, BMP, TGA or Radiance HDR as OpenImageIO does: values as stored (8- and 16-bit
// formats divided by their maximum, no transfer curve undone), channels named as OpenImageIO names
// them (Y, Y A, R G B, R G B A). Throws InputError naming the path.
Image readImageWithStb(const std::string& path);

} // namespace obscura::io
