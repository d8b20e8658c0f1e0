// DAQ data as numpy: a lossless feed of a Model's channels (Model.record and Model.stream build on
// it), and recording files read without a session (caliper.Recording).
#include <chrono>
#include <cmath>
#include <thread>

#include "caliper/recording/recording.h"
#include "model_object.h"

namespace caliper::python {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;

namespace {

// Times [s] and a (samples x values_per_sample) array, moved out of `times` and `data`.
py::tuple Block(std::vector<double>& times, std::vector<double>& data, size_t width) {
  py::array_t<double> t(static_cast<py::ssize_t>(times.size()));
  std::copy(times.begin(), times.end(), t.mutable_data());
  py::array_t<double> d({static_cast<py::ssize_t>(times.size()), static_cast<py::ssize_t>(width)});
  std::copy(data.begin(), data.end(), d.mutable_data());
  times.clear();
  data.clear();
  return py::make_tuple(t, d);
}

// A lossless subscription whose batches gather here until taken (the Model's stepping waits for
// this consumer when it steps or runs as fast as possible).
class Feed {
 public:
  Feed(std::shared_ptr<ModelObject> model, const py::object& ids, uint32_t every)
      : model_(std::move(model)), ids_(IdList(ids, "ids")) {
    if (ids_.empty()) throw py::value_error("ids must name at least one channel");
    if (every < 1) throw py::value_error("every must be >= 1 step");
    every_ = every;
    ModelObject& m = *model_;
    D::ChannelInfoSeq_var all = m.Run([&] { return m.ref.model->list("*"); });
    for (const auto& id : ids_)
      for (CORBA::ULong i = 0; i < all->length(); ++i)
        if (id == all[i].id.in()) {
          channels_.append(ChannelObject(all[i]));
          width_hint_ += static_cast<uint64_t>(all[i].rows) * all[i].cols;
        }
    py::gil_scoped_release release;
    CallScope scope(m.s.timeout_s);
    feed_ = std::make_unique<client::DataFeed>(
        *m.s.session, m.ref, ids_, every, true, [this](const client::Batch& b) {
          if (b.number != next_batch_) gaps_ += b.number - next_batch_;
          next_batch_ = b.number + 1;
          width_ = b.values_per_sample;
          times_.insert(times_.end(), b.times, b.times + b.count);
          data_.insert(data_.end(), b.data, b.data + b.count * b.values_per_sample);
          received_ += b.count;
        });
  }
  ~Feed() {
    try {
      Close();
    } catch (const std::exception&) {
      // the Model or this process's ORB is going: nothing left to end
    }
  }

  // Steps the Model `steps` (in pieces, so that Ctrl-C is seen) and takes every sample.
  py::tuple Step(uint64_t steps) {
    const uint64_t values = (steps + every_ - 1) / every_ * width_hint_;
    if (values > kMaxValues)
      throw client::LimitExceededError(
          model_->ref.name + ": " + std::to_string(steps) + " steps of these channels are " +
              std::to_string(values) + " values, more than one call keeps in memory (" +
              std::to_string(kMaxValues) + "); take them in blocks (Model.stream)",
          kMaxValues);
    uint64_t done = 0;
    while (done < steps) {
      const uint64_t piece = std::min<uint64_t>(steps - done, 20000);
      const CORBA::ULong ran = model_->Run(
          [&] { return model_->ref.model->step(static_cast<CORBA::ULong>(piece)); }, kLongCallS);
      done += ran;
      if (ran < piece) break;  // faulted, paused or stopped meanwhile, or a replay's end
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    py::tuple block = Take(10.0, true);
    RaiseIfFaulted(*model_, steps, done);
    return block;
  }

  // What has arrived. At rest, after waiting up to `wait_s` [s] for the samples the Model has
  // taken (its last, partial batch comes within a push poll); a running Model is not waited for
  // (its batch in progress fills as it runs). With `complete`, Failure when some are missing.
  py::tuple Take(double wait_s, bool complete = false) {
    if (!(wait_s >= 0 && wait_s <= 3600)) throw py::value_error("wait_s must be 0 to 3600 s");
    uint64_t taken = 0, received = 0, gaps = 0;
    std::vector<double> times, data;
    size_t width = 0;
    {
      py::gil_scoped_release release;
      CallScope scope(model_->s.timeout_s);
      M::SimulationStatus_var state = client::StatusOf(model_->ref);
      const bool running = state->state == M::RUNNING;
      const auto until = std::chrono::steady_clock::now() +
                         std::chrono::microseconds(static_cast<int64_t>(wait_s * 1e6));
      while (true) {
        taken = feed_->Status().samples;
        {
          std::lock_guard<std::mutex> lock(feed_->mutex());
          if (running || received_ >= taken) break;
        }
        if (std::chrono::steady_clock::now() >= until) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      // out of the callback's reach before any Python object is made
      std::lock_guard<std::mutex> lock(feed_->mutex());
      times.swap(times_);
      data.swap(data_);
      width = width_;
      received = received_;
      gaps = gaps_;
    }
    if (gaps > 0)
      throw client::Failure(model_->ref.name + ": " + std::to_string(gaps) +
                            " batches of the lossless feed were lost (the Model drops batches "
                            "while it runs at a real-time factor above 0 and this client lags)");
    if (complete && received < taken)
      throw client::Failure(model_->ref.name + ": " + std::to_string(taken - received) + " of " +
                            std::to_string(taken) + " samples did not arrive within " +
                            std::to_string(wait_s) + " s");
    return Block(times, data, width);
  }

  void Close() {
    if (!feed_) return;
    py::gil_scoped_release release;
    CallScope scope(model_ ? model_->s.timeout_s : 5.0);
    feed_->Close();
  }

  const py::list& channels() const { return channels_; }

 private:
  std::shared_ptr<ModelObject> model_;
  std::vector<std::string> ids_;
  py::list channels_;
  std::unique_ptr<client::DataFeed> feed_;
  // written by the callback under feed_->mutex()
  std::vector<double> times_, data_;
  size_t width_ = 0;
  uint32_t every_ = 1;
  uint64_t width_hint_ = 0;  // values per sample, from the channels' shapes
  // the most values Step gathers in one call (8 GB of float64)
  static constexpr uint64_t kMaxValues = 1000000000;
  uint64_t received_ = 0, next_batch_ = 1, gaps_ = 0;
};

py::object Header(const recording::Reader& r) {
  const recording::Header& h = r.header();
  py::list channels;
  for (const auto& c : h.channels)
    channels.append(py::module_::import("caliper.model")
                        .attr("Channel")(c.id, c.unit,
                                         py::tuple(py::cast(ChannelShape(c.rows, c.cols))), false,
                                         false, ""));
  py::dict out;
  out["model_name"] = h.model_name;
  out["scene_file_name"] = h.scene_file_name;
  out["time_step_s"] = h.time_step;
  out["keyframe_every"] = h.keyframe_every;
  out["channels_every"] = h.channels_every;
  out["first_step"] = h.first_step;
  out["last_step"] = r.last_step();
  out["duration_s"] = r.duration();
  out["engine"] = h.engine;
  out["channels"] = channels;
  return std::move(out);
}

void BindRecordingFile(py::module_& m) {
  py::class_<recording::Reader>(m, "_RecordingFile")
      .def(py::init<const std::string&>(), py::arg("path"))
      .def("header", &Header)
      .def("keyframes",
           [](const recording::Reader& r) {
             std::vector<uint64_t> steps = r.keyframe_steps();
             std::vector<double> times;
             for (uint64_t s : steps) times.push_back(r.KeyframeAtOrBefore(s).time);
             return py::make_tuple(py::array(py::cast(steps)), py::array(py::cast(times)));
           })
      .def("events",
           [](const recording::Reader& r, uint64_t first, uint64_t last) {
             py::list out;
             py::object event = py::module_::import("caliper.recording").attr("Event");
             for (auto& e : r.Events(first, last))
               out.append(event(e.step, e.kind, e.target, py::array(py::cast(e.values))));
             return out;
           })
      .def("samples",
           [](const recording::Reader& r, uint64_t first, uint64_t last) {
             std::vector<double> times, data;
             size_t width = 0;
             std::vector<uint64_t> steps;
             for (auto& s : r.Samples(first, last)) {
               steps.push_back(s.step);
               times.push_back(s.time);
               width = s.values.size();
               data.insert(data.end(), s.values.begin(), s.values.end());
             }
             py::tuple block = Block(times, data, width);
             return py::make_tuple(py::array(py::cast(steps)), block[0], block[1]);
           })
      .def("log",
           [](const recording::Reader& r) {
             py::list out;
             for (auto& l : r.Log())
               out.append(py::make_tuple(l.time, l.priority, l.category, l.component, l.message));
             return out;
           })
      .def("scenes",
           [](const recording::Reader& r) {
             py::list out;
             for (auto& s : r.scenes())
               out.append(py::make_tuple(s.version, s.step, s.file_name, py::bytes(s.bytes)));
             return out;
           })
      .def("export_csv", &recording::Reader::ExportCsv, py::arg("csv_path"));
}

}  // namespace

void BindData(py::module_& m) {
  py::class_<Feed>(m, "_Feed")
      .def(py::init<std::shared_ptr<ModelObject>, const py::object&, uint32_t>(), py::arg("model"),
           py::arg("ids"), py::arg("every") = 1)
      .def_property_readonly("channels", &Feed::channels)
      .def("step", &Feed::Step, py::arg("steps"))
      .def("take", &Feed::Take, py::arg("wait_s") = 0.0, py::arg("complete") = false)
      .def("close", &Feed::Close);
  BindRecordingFile(m);
}

}  // namespace caliper::python
