// exr_reader.h — an OpenEXR reader for builds without OpenImageIO (-DOBSCURA_WITH_OPENIMAGEIO=OFF):
// what tools/gpu's bundle needs to read the photographs `recover` takes (Cycles writes half-float
// ZIP), the EXR that render, relight and converge write (OpenImageIO's float ZIP, or
// exr_writer.h's uncompressed float) and a relighting state's transport.
//
// It reads single-part scan-line files (openexr.com, "OpenEXR File Layout") whose compression is
// NONE, RLE, ZIPS or ZIP, with HALF, FLOAT and UINT channels sampled at every pixel. Anything else
// (tiles, several parts, deep data, PIZ, PXR24, B44 and DWA compression, subsampled channels) is
// refused with an InputError that names the file and what it holds. Channels come in the order
// OpenImageIO gives them, so that both builds index an image alike: the layers (the names' part
// before the last '.') with the unnamed one first, and in each layer R, G, B, A before the rest,
// which keep the file's (sorted) order. A UINT channel reads as OpenImageIO reads it, normalised:
// u / (2^32 - 1). Text attributes named "obscura:..." are read back, as image_io.h's readImage does
// through OpenImageIO.
#pragma once
#include <string>

#include "io/image_io.h"

namespace obscura::io {

// Reads `path`. Throws InputError naming `path` and the problem: not an EXR, a layout or
// compression it does not read, or a file cut short or corrupt.
Image readExr(const std::string& path);

} // namespace obscura::io
