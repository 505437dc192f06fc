// exr_writer.h — a plain OpenEXR writer for builds without OpenImageIO (-DOBSCURA_WITH_OPENIMAGEIO=OFF):
// single part, scan lines, 32-bit float channels, no compression. Larger files than
// OpenImageIO's zip-compressed ones, but every EXR reader reads them, so a bundle built to travel
// (tools/gpu/) still writes what render, relight and converge write.
#pragma once
#include <string>

#include "io/image_io.h"

namespace obscura::io {

// Writes `image` to `path` (all channels, as float). Throws InputError naming `shownPath` (the
// name the user gave; `path` may be a temporary file beside it).
void writeUncompressedExr(const std::string& path, const std::string& shownPath, const Image& image);

} // namespace obscura::io
