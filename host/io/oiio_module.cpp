// oiio_module.cpp — libobscura_oiio.so (CMake target obscura_oiio): OpenImageIO behind
// io/oiio_codec.h, loaded by the core on first use. Built on its own, not into obscura_core.
#include <OpenImageIO/imageio.h>
#if defined(__SSE2__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

#include "io/oiio_codec.h"

namespace obscura::io {
namespace {

// OpenImageIO converts a half to a float in this thread's SSE mode: one that flushes denormals (a
// library built with -ffast-math sets it at load; Embree advises it) reads every half subnormal,
// 2^-24 to 2^-14, as 0. A photograph's dark pixels are such values (the classroom's shot 1 has 103
// of them), and a recovery merged other pixels for it. So reading keeps denormals whatever the
// caller's mode, and puts that mode back after.
class DenormalsKept {
public:
#if defined(__SSE2__)
  DenormalsKept() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ & ~unsigned(_MM_FLUSH_ZERO_MASK | _MM_DENORMALS_ZERO_MASK)); }
  ~DenormalsKept() { _mm_setcsr(saved_); }
  DenormalsKept(const DenormalsKept&) = delete;
  DenormalsKept& operator=(const DenormalsKept&) = delete;

private:
  unsigned saved_;
#endif
};

class OpenImageIoCodec final : public OiioCodec {
public:
  std::string writeFloat(const std::string& path, const Image& image) const override {
    OIIO::ImageSpec spec(image.width, image.height, image.channelCount(), OIIO::TypeDesc::FLOAT);
    spec.channelnames = image.channels;
    spec.attribute("compression", "zip");
    for (const auto& [name, text] : image.attributes) spec.attribute(name, text);
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return "cannot write this image format: " + OIIO::geterror();
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data()) || !out->close())
      return "cannot write: " + out->geterror();
    return {};
  }

  std::string read(const std::string& path, Image& image) const override {
    const DenormalsKept denormals;
    auto in = OIIO::ImageInput::open(path);
    if (!in) return "cannot read image: " + OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    image.width = spec.width;
    image.height = spec.height;
    image.channels = spec.channelnames;
    for (const OIIO::ParamValue& p : spec.extra_attribs)
      if (p.type() == OIIO::TypeDesc::STRING && p.name().string().rfind("obscura:", 0) == 0)
        image.attributes.emplace_back(p.name().string(), p.get_string());
    image.pixels.resize(std::size_t(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
      return "cannot read image: " + in->geterror();
    in->close();
    return {};
  }
};

} // namespace
} // namespace obscura::io

extern "C" const obscura::io::OiioCodec* obscura_oiio_codec() {
  static const obscura::io::OpenImageIoCodec codec;
  return &codec;
}
