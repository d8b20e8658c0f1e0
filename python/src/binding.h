#pragma once
// The Python package's extension module `caliper._caliper`: pybind11 over the client library
// (libs/client). One file per part: errors, the session, a Model, DAQ data (records, streams,
// recording files) and work spread over Models (experiments, batches, calibration costs).
//
// Threads: every call that waits on the network releases the GIL and runs with a per-thread call
// timeout (CallScope), so a Python thread can run while another waits on a Model.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "caliper/client/client.h"

namespace caliper::python {

namespace py = pybind11;

/// The session a Python object came from; the ORB lives until the interpreter ends.
struct SessionHandle {
  std::shared_ptr<client::Session> session;
  double timeout_s = 5.0;  ///< the deadline of ordinary calls [s]
};

/// The deadline of calls that take as long as their work (load, step, experiments) [s].
constexpr double kLongCallS = 3600;

/// For its lifetime, the calling thread's ORB calls have `timeout_s` as deadline (0: none); the
/// thread is made known to omniORB once.
class CallScope {
 public:
  explicit CallScope(double timeout_s);
  ~CallScope();
  CallScope(const CallScope&) = delete;
  CallScope& operator=(const CallScope&) = delete;
};

/// The Python exception classes of caliper.errors raised for the library's errors, the ones
/// the recording and file readers throw, and CORBA's.
void BindErrors(py::module_& m);
void BindSession(py::module_& m);
void BindModel(py::module_& m);
void BindData(py::module_& m);
void BindWork(py::module_& m);
void BindLockstep(py::module_& m);

/// A sequence of finite floats from `value` (a number or an array-like), TypeError/ValueError
/// naming `argument` when it is not one.
std::vector<double> FiniteValues(const py::handle& value, const char* argument);

/// `ids` as a list of strings: one string or an iterable of them; TypeError naming `argument`.
std::vector<std::string> IdList(const py::handle& ids, const char* argument);

/// The numpy shape of a channel of rows x cols values: () for 1 x 1, (rows,) for a column,
/// (rows, cols) otherwise.
std::vector<py::ssize_t> ChannelShape(uint32_t rows, uint32_t cols);

}  // namespace caliper::python
