// caliper.Model's session recordings (the Model writes one SQLite file on its host) and replay:
// open, seek, fork.
#include <cmath>

#include "caliper/client/scene_transfer.h"
#include "model_object.h"

namespace caliper::python {

namespace M = ::Caliper::Simulation;

namespace {

py::object RecordStatusObject(const M::RecordStatus& r) {
  return py::module_::import("caliper.model")
      .attr("RecordStatus")(static_cast<bool>(r.recording), std::string(r.path.in()), r.first_step,
                            r.steps, r.bytes, std::string(r.error.in()));
}

py::object ReplayStatusObject(const M::ReplayStatus& r) {
  return py::module_::import("caliper.model")
      .attr("ReplayStatus")(static_cast<bool>(r.replaying), std::string(r.path.in()), r.first_step,
                            r.last_step, r.step, r.start_time, r.end_time, r.time);
}

py::object StartRecording(ModelObject& m, const std::string& path, const py::object& channels,
                          uint32_t every, uint32_t keyframe_every, uint64_t max_bytes) {
  if (every < 1) throw py::value_error("every must be >= 1 step");
  if (keyframe_every < 1 || keyframe_every > 1000)
    throw py::value_error("keyframe_every must be 1 to 1000 steps");
  M::RecordOptions options;
  options.keyframe_every = keyframe_every;
  options.channels_every = every;
  const std::vector<std::string> ids = IdList(channels, "channels");
  options.channels.length(static_cast<CORBA::ULong>(ids.size()));
  for (size_t i = 0; i < ids.size(); ++i)
    options.channels[static_cast<CORBA::ULong>(i)] = ids[i].c_str();
  options.max_bytes = max_bytes;
  M::RecordStatus_var r =
      m.Run([&] { return m.ref.model->start_recording(path.c_str(), options); });
  return RecordStatusObject(r.in());
}

}  // namespace

void BindSessionRecording(py::class_<ModelObject, std::shared_ptr<ModelObject>>& c) {
  c.def("start_recording", &StartRecording, py::arg("path"),
        py::arg("channels") = std::vector<std::string>{}, py::arg("every") = 1,
        py::arg("keyframe_every") = 100, py::arg("max_bytes") = 0,
        R"doc(The Model records its session from now on into `path` (a file name below its write
directory, on its host; never overwritten): keyframes every `keyframe_every` steps, every command,
edit and log record, and `channels` every `every` steps. `max_bytes` > 0 stops it beyond that
size. Read the file with caliper.Recording.)doc")
      .def(
          "stop_recording",
          [](ModelObject& m) {
            M::RecordStatus_var r = m.Run([&] { return m.ref.model->stop_recording(); });
            return RecordStatusObject(r.in());
          },
          "Ends the recording; returns its final status (steps, bytes).")
      .def(
          "recording_status",
          [](ModelObject& m) {
            M::RecordStatus_var r = m.Run([&] { return m.ref.model->recording_status(); });
            return RecordStatusObject(r.in());
          },
          "Whether it records, where, how much, and why it stopped early if it did.")
      .def(
          "open_replay",
          [](ModelObject& m, const std::string& path, bool send) {
            const client::OpenedReplay opened = m.Run(
                [&] { return client::OpenReplay(m.ref.model, path, m.ref.local, send); },
                kLongCallS);
            return ReplayStatusObject(opened.status);
          },
          py::arg("path"), py::arg("send") = false,
          "The Model replays a recording, paused at its start; start(), step() and seek() play "
          "it, fork() simulates on. A file the Model cannot read itself (on another host, outside "
          "its directories, or send=True) goes by content; a name that is no file here is the Model's "
          "(relative: from its write directory, where start_recording writes).")
      .def(
          "seek",
          [](ModelObject& m, double time_s) {
            if (!std::isfinite(time_s)) throw py::value_error("time_s must be finite");
            M::ReplayStatus_var r = m.Run([&] { return m.ref.model->seek(time_s); }, kLongCallS);
            return ReplayStatusObject(r.in());
          },
          py::arg("time_s"), "Goes to `time_s` of simulated time in the replay [s].")
      .def(
          "replay_status",
          [](ModelObject& m) {
            M::ReplayStatus_var r = m.Run([&] { return m.ref.model->replay_status(); });
            return ReplayStatusObject(r.in());
          },
          "Whether it replays, the file, the step and time [s] against the recording's end.")
      .def(
          "fork", [](ModelObject& m) { m.Run([&] { m.ref.model->fork(); }); },
          "Ends the replay where it is: commands and edits are taken again from here.");
}

}  // namespace caliper::python
