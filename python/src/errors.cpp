// errors.cpp — the renderer's exceptions as Python's: a bad scene file or option raises
// obscura.InputError (a ValueError) with the command line's message (the file and element named),
// a device failure obscura.DeviceError (a RuntimeError); the interpreter never sees a crash.
#include <new>

#include <vulkan/vulkan_raii.hpp>

#include "bindings.h"
#include "core/error.h"

namespace py = pybind11;

namespace obscura::python {

void bindErrors(py::module_& m) {
  static py::exception<InputError> inputError(m, "InputError", PyExc_ValueError);
  static py::exception<DeviceError> deviceError(m, "DeviceError", PyExc_RuntimeError);
  inputError.doc() = "Bad input: a scene, photo or state file, an option or an edit (the message names it).";
  deviceError.doc() = "The Vulkan device failed: none found, out of memory, device lost.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(inputError.ptr(), e.what());
    } catch (const DeviceError& e) {
      PyErr_SetString(deviceError.ptr(), e.what());
    } catch (const vk::SystemError& e) {
      PyErr_SetString(deviceError.ptr(), (std::string("Vulkan error: ") + e.what()).c_str());
    }
  });
}

} // namespace obscura::python
