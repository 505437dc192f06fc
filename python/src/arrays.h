// arrays.h — images as NumPy arrays without a copy: float32 views (H x W x C) into an io::Image
// that the arrays keep alive, and JSON as Python objects. The views are writeable: NumPy exports
// no read-only array through DLPack, and a result's memory is its caller's.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "io/image_io.h"

namespace obscura::python {

// Channels [first, first + count) of `image` as an H x W x count view (strided: the image's
// channels are interleaved), keeping `image` alive.
pybind11::array channelView(const std::shared_ptr<const io::Image>& image, int first, int count);
// Every AOV of `image` ("combined.R/G/B" -> "combined": H x W x 3; plain R, G, B -> "rgb"), in
// channel order, as views;
// channels whose name starts with one of `skipPrefixes` are left out.
pybind11::dict aovViews(const std::shared_ptr<const io::Image>& image, const std::vector<std::string>& skipPrefixes = {});
// The light layers ("light.<name>.R/G/B", render::lightLayers) as one L x H x W x 3 view.
pybind11::array lightStackView(const std::shared_ptr<const io::Image>& layers);
// Packed RGBA8 pixels (R in the low byte) as an H x W x 4 uint8 array.
pybind11::array rgba8Array(int width, int height, const std::vector<std::uint32_t>& pixels);
// A JSON value as Python's json.loads makes it.
pybind11::object pythonValue(const nlohmann::json& value);

} // namespace obscura::python
