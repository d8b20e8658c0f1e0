// caliper._caliper: the extension module of the Python package (binding.h).
#include "binding.h"

PYBIND11_MODULE(_caliper, m) {
  using namespace caliper::python;
  m.doc() = "Caliper's client library (libs/client) for Python; use the package `caliper`.";
  BindErrors(m);
  BindSession(m);
  BindModel(m);
  BindData(m);
  BindWork(m);
  BindLockstep(m);
}
