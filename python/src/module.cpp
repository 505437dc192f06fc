// module.cpp — obscura._obscura, the compiled half of the `obscura` Python package.
#include "bindings.h"

PYBIND11_MODULE(_obscura, m) {
  m.doc() = "Obscura's renderer, relighting and edit session (see the package obscura)";
  obscura::python::bindErrors(m);
  obscura::python::bindDevices(m);
  obscura::python::bindScene(m);
  obscura::python::bindResult(m);
  obscura::python::bindSession(m);
  obscura::python::bindCommands(m);
}
