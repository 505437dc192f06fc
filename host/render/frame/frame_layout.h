// frame_layout.h — how a frame's storage is split into bands of whole rows.
//
// Frame-lifetime buffers grow with pixels x lights (a basis buffer per light, SPEC §3); a
// device's per-buffer limit (lavapipe: 128 MiB) would refuse a 1080p frame or modern-hall's 13
// lights at 800x600 in one buffer. So the frame is cut into bands of rows, each with its own
// buffers, each no larger than the limit, and every per-pixel pass is dispatched once per band.
// Bands change where pixels are stored, never what they hold (shaders/lib/band.glsl).
#pragma once
#include <cstdint>
#include <vector>

namespace obscura::render {

struct FrameBand {
  std::uint32_t firstRow = 0;
  std::uint32_t rows = 0;
};

struct FrameLayout {
  std::uint32_t width = 0, height = 0;
  std::vector<FrameBand> bands;

  std::uint64_t bandPixels(std::size_t band) const { return std::uint64_t(width) * bands[band].rows; }
  std::uint64_t pixels() const { return std::uint64_t(width) * height; }
  std::uint32_t bandCount() const { return static_cast<std::uint32_t>(bands.size()); }

  // Bands as tall as `largestBytesPerPixel` (the widest per-pixel buffer) lets them be within
  // `maxBufferBytes`, all of one height but the last. Throws InputError when even one row does
  // not fit; `what` names the cause for that message.
  static FrameLayout split(std::uint32_t width, std::uint32_t height, std::uint64_t largestBytesPerPixel,
                           std::uint64_t maxBufferBytes, const char* what);
};

} // namespace obscura::render
