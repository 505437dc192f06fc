// commands.cpp — the command line's commands run in the Python process (app/command_line.h
// runCommand), with their errors raised as Python exceptions, and images read into arrays: what
// obscura.recover and obscura.remodel (python/obscura/__init__.py) are made of, so that they do
// exactly what `obscura recover` and `obscura remodel` do.
#include <memory>

#include <pybind11/stl.h>

#include "app/command_line.h"
#include "app/commands.h"
#include "arrays.h"
#include "bindings.h"
#include "devices.h"
#include "io/image_io.h"

namespace py = pybind11;

namespace obscura::python {

void bindCommands(py::module_& m) {
  m.def(
      "run_command",
      [](const std::vector<std::string>& args) {
        py::gil_scoped_release release;
        std::lock_guard work(deviceWork());
        app::runCommand(args);
      },
      py::arg("args"),
      "Runs one obscura command in this process, e.g. run_command(['relight', 'scene.gltf', '--edits', "
      "'e.json', '-o', 'out']): the same options and outputs as the command line, its errors raised "
      "(InputError, DeviceError) instead of an exit status.");
  m.def(
      "read_image",
      [](const std::string& path) {
        std::shared_ptr<const io::Image> image;
        {
          py::gil_scoped_release release;
          image = std::make_shared<const io::Image>(io::readImage(path));
        }
        return aovViews(image);
      },
      py::arg("path"),
      "An image file (EXR with its layers, PNG, JPEG, HDR, ...) as a dict of layer name -> float32 "
      "array H x W x C ('combined', 'albedo', ...; plain R, G, B channels are 'rgb'). PNG values are "
      "0..1, not decoded from sRGB.");
}

} // namespace obscura::python
