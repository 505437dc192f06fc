#include "devices.h"

#include <map>
#include <tuple>

#include <pybind11/stl.h>

#include "bindings.h"
#include "gpu/buffer.h"

namespace py = pybind11;

namespace obscura::python {
namespace {

using DeviceKey = std::tuple<std::string, bool, std::string>;

std::mutex devicesMutex;
std::map<DeviceKey, std::shared_ptr<Device>>& devices() {
  static auto* kept = new std::map<DeviceKey, std::shared_ptr<Device>>(); // outlives the interpreter's teardown
  return *kept;
}

py::dict deviceInfo(const gpu::DeviceInfo& d, bool chosen) {
  py::dict info;
  info["index"] = d.index;
  info["name"] = d.name;
  info["type"] = d.type;
  info["driver"] = d.driver;
  info["api"] = d.apiVersion;
  info["device_local_bytes"] = d.deviceLocalBytes;
  info["subgroup_size"] = d.subgroupSize;
  info["chosen"] = chosen;
  return info;
}

} // namespace

std::shared_ptr<Device> sharedDevice(const app::DeviceOptions& options) {
  const DeviceKey key{options.device, options.validate, options.traversal};
  std::lock_guard lock(devicesMutex);
  auto& kept = devices();
  auto found = kept.find(key);
  if (found != kept.end()) return found->second;
  auto device = std::make_shared<Device>(options.contextOptions());
  kept.emplace(key, device);
  return device;
}

void bindDevices(py::module_& m) {
  m.def(
      "devices",
      [] {
        std::uint32_t chosen = 0;
        py::list out;
        for (const auto& d : gpu::Context::listDevices(&chosen)) out.append(deviceInfo(d, d.index == chosen));
        return out;
      },
      "The Vulkan devices the loader reports (as `obscura info` lists them), the automatic choice marked.");
  m.def(
      "release_devices",
      [] {
        std::lock_guard lock(devicesMutex);
        devices().clear();
      },
      "Drops the module's kept Vulkan contexts and their compiled pipelines (sessions still open keep "
      "theirs until closed). The next render makes its context again.");
  m.def("validation_messages", &gpu::Context::validationMessages,
        "The Khronos validation layer's warnings and errors so far (with OBSCURA_VALIDATE=1 or "
        "validate=True), all contexts together.");
  m.def("buffer_bytes_in_use", &gpu::bufferBytesInUse,
        "Device memory held by this process's buffers now (every renderer, session and context): what "
        "returns to its level when results are dropped and sessions closed.");
}

} // namespace obscura::python
