// oiio_codec.h — the part of image IO that needs OpenImageIO (EXR in and out, and the formats stb
// does not read), in a module of its own, libobscura_oiio.so, that is loaded the first time it is
// needed. OpenImageIO links ~260 shared libraries, whose loading cost every process ~0.45 s of CPU
// at start (most of a short `obscura` command, and of every test process) when the core linked it;
// a command that writes only PNG (stb, io/stb_codec.h) now never loads them.
//
// The module is built with the program, by the same compiler (CMake target obscura_oiio), so the
// interface is a C++ class; it reports failures as text and the caller throws, so no exception
// crosses the module's boundary.
#pragma once
#include <string>

#include "io/image_io.h"

namespace obscura::io {

class OiioCodec {
public:
  virtual ~OiioCodec() = default;
  // Writes every channel of `image` as 32-bit float, zip-compressed where the format has it (EXR),
  // with its attributes in the header. Returns "" or OpenImageIO's reason.
  virtual std::string writeFloat(const std::string& path, const Image& image) const = 0;
  // Reads `path` (linear floats as stored; 8- and 16-bit formats / their maximum) and the
  // attributes named "obscura:...". Returns "" or OpenImageIO's reason.
  virtual std::string read(const std::string& path, Image& image) const = 0;
};

// The module's codec, loaded on the first call (beside the binary or library that holds this
// code, beside the executable, then on the loader's search path). Throws InputError naming
// `forPath` and every place tried when it cannot be loaded.
const OiioCodec& oiioCodec(const std::string& forPath);

} // namespace obscura::io

// The module's one exported symbol.
extern "C" const obscura::io::OiioCodec* obscura_oiio_codec();
