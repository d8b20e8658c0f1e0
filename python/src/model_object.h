#pragma once
// caliper.Model's C++ side: a Model of a session, called with the session's deadline and the
// GIL released.

#include <map>
#include <mutex>
#include <string>
#include <utility>

#include "binding.h"

namespace caliper::python {

struct ModelObject {
  SessionHandle s;
  client::ModelRef ref;

  /// Runs `f` on the Model with the GIL released and a call deadline of `timeout_s` (the
  /// session's when < 0), the Model's exceptions turned into the library's (client::Call).
  template <class F>
  auto Run(F&& f, double timeout_s = -1) -> decltype(f()) {
    py::gil_scoped_release release;
    CallScope scope(timeout_s < 0 ? s.timeout_s : timeout_s);
    return client::Call(ref, std::forward<F>(f));
  }
};

/// After a step request that ran `done` of `asked` steps: raises caliper.RunFailed (with
/// .steps) when the Model faulted on the way.
void RaiseIfFaulted(ModelObject& m, uint64_t asked, uint64_t done);

/// Session.model(name): the Model bound as `name` (model1@hostb is hostb/model1).
std::shared_ptr<ModelObject> OpenModel(SessionHandle& s, const std::string& name);

/// A Python Channel for a DAQ channel description.
py::object ChannelObject(const ::Caliper::Daq::ChannelInfo& c);

/// The values of one channel as a numpy array of its shape (ChannelShape).
py::array_t<double> ChannelArray(const double* values, uint32_t rows, uint32_t cols);

/// Model methods bound by other files: scene editing and pulls (edit.cc), recordings and replay
/// (session_recording.cc). Records and streams are caliper.Model's Python methods on _Feed.
void BindEditing(py::class_<ModelObject, std::shared_ptr<ModelObject>>& c);
void BindSessionRecording(py::class_<ModelObject, std::shared_ptr<ModelObject>>& c);

}  // namespace caliper::python
