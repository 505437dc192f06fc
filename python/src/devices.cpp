#include "devices.h"

#include <pybind11/stl.h>

#include "bindings.h"
#include "gpu/buffer.h"

namespace py = pybind11;

namespace obscura::python {
namespace {

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

std::mutex& deviceWork() {
  static auto* work = new std::mutex(); // outlives the interpreter's teardown, as the contexts do
  return *work;
}

std::shared_ptr<gpu::Context> sharedContext(const app::DeviceOptions& options) {
  return app::commandContext(options);
}

void bindDevices(py::module_& m) {
  // The module runs many renders and commands: one context per device choice serves them all.
  app::keepCommandContexts(true);
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
        py::gil_scoped_release release;
        std::lock_guard work(deviceWork());
        app::keepCommandContexts(false); // drops them
        app::keepCommandContexts(true);
      },
      "Drops the module's kept Vulkan contexts and their compiled pipelines (sessions still open keep "
      "theirs until closed). The next render or command makes its context again.");
  m.def("validation_messages", &gpu::Context::validationMessages,
        "The Khronos validation layer's warnings and errors so far (with OBSCURA_VALIDATE=1 or "
        "validate=True), all contexts together.");
  m.def("buffer_bytes_in_use", &gpu::bufferBytesInUse,
        "Device memory held by this process's buffers now (every renderer, session and context): what "
        "returns to its level when results are dropped and sessions closed.");
}

} // namespace obscura::python
