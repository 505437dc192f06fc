// bindings.h — the parts of the `obscura` Python module (python/obscura/__init__.py re-exports
// them from obscura._obscura), each registered by its own file:
//   errors.cpp          InputError, DeviceError: the command line's messages as Python exceptions
//   devices.cpp         the Vulkan contexts the module's renders share (one per device choice)
//   scene.cpp           Scene: a glTF opened once, its lights, objects, cameras and bounds (info)
//   result.cpp          render() and load_state(): a frame's AOVs, light stack, relight()
//   session.cpp         Session: the edit session of `relight --edits` and the window
//   commands.cpp        recover() and remodel(), the commands run in-process
#pragma once
#include <pybind11/pybind11.h>

namespace obscura::python {

void bindErrors(pybind11::module_& m);
void bindDevices(pybind11::module_& m);
void bindScene(pybind11::module_& m);
void bindResult(pybind11::module_& m);
void bindSession(pybind11::module_& m);
void bindCommands(pybind11::module_& m);

} // namespace obscura::python
