#include "arrays.h"

#include <cstring>

namespace py = pybind11;

namespace obscura::python {
namespace {

// A capsule that holds a reference to `image` for as long as an array uses its memory.
py::capsule keepAlive(const std::shared_ptr<const io::Image>& image) {
  return py::capsule(new std::shared_ptr<const io::Image>(image),
                     [](void* p) { delete static_cast<std::shared_ptr<const io::Image>*>(p); });
}

// "albedo.R" -> "albedo"; channels without a layer (an image's plain R, G, B) are "rgb".
std::string aovOf(const std::string& channel) {
  const auto dot = channel.rfind('.');
  return dot == std::string::npos ? "rgb" : channel.substr(0, dot);
}

} // namespace

py::array channelView(const std::shared_ptr<const io::Image>& image, int first, int count) {
  const auto f = static_cast<py::ssize_t>(sizeof(float));
  const auto channels = static_cast<py::ssize_t>(image->channelCount());
  const std::vector<py::ssize_t> shape{image->height, image->width, count};
  const std::vector<py::ssize_t> strides{image->width * channels * f, channels * f, f};
  const float* data = image->pixels.data() + first;
  return py::array_t<float>(shape, strides, data, keepAlive(image));
}

py::dict aovViews(const std::shared_ptr<const io::Image>& image, const std::vector<std::string>& skipPrefixes) {
  py::dict out;
  const auto& names = image->channels;
  for (std::size_t c = 0; c < names.size();) {
    const std::string aov = aovOf(names[c]);
    std::size_t end = c + 1;
    while (end < names.size() && aovOf(names[end]) == aov) ++end;
    bool skip = false;
    for (const auto& prefix : skipPrefixes) skip = skip || names[c].rfind(prefix, 0) == 0;
    if (!skip) out[py::str(aov)] = channelView(image, static_cast<int>(c), static_cast<int>(end - c));
    c = end;
  }
  return out;
}

py::array lightStackView(const std::shared_ptr<const io::Image>& layers) {
  const auto f = static_cast<py::ssize_t>(sizeof(float));
  const auto channels = static_cast<py::ssize_t>(layers->channelCount());
  const std::vector<py::ssize_t> shape{channels / 3, layers->height, layers->width, 3};
  const std::vector<py::ssize_t> strides{3 * f, layers->width * channels * f, channels * f, f};
  return py::array_t<float>(shape, strides, layers->pixels.data(), keepAlive(layers));
}

py::array rgba8Array(int width, int height, const std::vector<std::uint32_t>& pixels) {
  py::array_t<std::uint8_t> out({height, width, 4});
  std::memcpy(out.mutable_data(), pixels.data(), pixels.size() * sizeof(std::uint32_t)); // R in the low byte: R, G, B, A
  return out;
}

py::object pythonValue(const nlohmann::json& value) {
  return py::module_::import("json").attr("loads")(value.dump());
}

} // namespace obscura::python
