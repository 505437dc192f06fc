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

// Rows [first, first + count) of an image: the part of it a frame holds (a farm's tile,
// `render --tile`). count 0: every row.
struct RowRange {
  std::uint32_t first = 0, count = 0;
  bool whole() const { return first == 0 && count == 0; }
};

struct FrameLayout {
  // The frame's own pixels: `width` x `height`. A frame may hold only some rows of the image the
  // camera sees (a tile): they start at row `firstRow` of an image `imageHeight` rows high. Bands'
  // firstRow are rows of that image (the shaders' pixel coordinates, so a tile's pixels are
  // bit-identical to the same pixels of the whole frame).
  std::uint32_t width = 0, height = 0;
  std::vector<FrameBand> bands;
  std::uint32_t firstRow = 0, imageHeight = 0;

  std::uint64_t bandPixels(std::size_t band) const { return std::uint64_t(width) * bands[band].rows; }
  // Where band `band` starts in the frame's own pixels (row-major, `height` rows).
  std::uint64_t bandFirstPixel(std::size_t band) const {
    return std::uint64_t(bands[band].firstRow - firstRow) * width;
  }
  std::uint64_t pixels() const { return std::uint64_t(width) * height; }
  std::uint32_t bandCount() const { return static_cast<std::uint32_t>(bands.size()); }

  // Bands as tall as `largestBytesPerPixel` (the widest per-pixel buffer) lets them be within
  // `maxBufferBytes`, all of one height but the last. Throws InputError when even one row does
  // not fit; `what` names the cause for that message.
  // `rows` (not whole) keeps only those rows of the `height`-row image (InputError when they are
  // not inside it).
  static FrameLayout split(std::uint32_t width, std::uint32_t height, std::uint64_t largestBytesPerPixel,
                           std::uint64_t maxBufferBytes, const char* what, RowRange rows = {});
};

} // namespace obscura::render
