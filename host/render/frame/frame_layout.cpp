#include "render/frame/frame_layout.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/error.h"

namespace obscura::render {

FrameLayout FrameLayout::split(std::uint32_t width, std::uint32_t height, std::uint64_t largestBytesPerPixel,
                               std::uint64_t maxBufferBytes, const char* what, RowRange rows) {
  if (width == 0 || height == 0) throw InputError("the image has no pixels");
  if (rows.whole()) rows.count = height;
  if (rows.count == 0 || rows.first >= height || rows.count > height - rows.first)
    throw InputError(fmt::format("rows {}..{} are not inside the {}-row image", rows.first,
                                 std::uint64_t(rows.first) + rows.count, height));
  const std::uint64_t rowBytes = std::uint64_t(width) * std::max<std::uint64_t>(largestBytesPerPixel, 1);
  if (rowBytes > maxBufferBytes)
    throw InputError(fmt::format("{}x{}: one row of {} needs {:.1f} MiB, more than the device's {:.1f} MiB per "
                                 "buffer; use fewer light groups (merge them) or a narrower image",
                                 width, height, what, static_cast<double>(rowBytes) / 1048576.0,
                                 static_cast<double>(maxBufferBytes) / 1048576.0));
  const auto rowsPerBand = static_cast<std::uint32_t>(std::min<std::uint64_t>(maxBufferBytes / rowBytes, rows.count));
  FrameLayout layout;
  layout.width = width;
  layout.height = rows.count;
  layout.firstRow = rows.first;
  layout.imageHeight = height;
  for (std::uint32_t row = 0; row < rows.count; row += rowsPerBand)
    layout.bands.push_back({.firstRow = rows.first + row, .rows = std::min(rowsPerBand, rows.count - row)});
  return layout;
}

} // namespace obscura::render
