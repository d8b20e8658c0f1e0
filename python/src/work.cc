// Work spread over Models: experiment files read here, runs on one Model or on a pool of every
// Model found (the client library's ModelPool: lost Models set aside, runs retried elsewhere),
// and a calibration file's cost for a parameter vector (libs/calibration's Evaluator).
#include <map>

#include "caliper/calibration/evaluator.h"
#include "caliper/experiment/experiment.h"
#include "model_object.h"

namespace caliper::python {

namespace M = ::Caliper::Simulation;

namespace {

// A run's recording as (channels, times [s], samples x values array).
py::tuple RecordingTuple(const experiment::Recording& r) {
  py::list channels;
  py::object channel = py::module_::import("caliper.model").attr("Channel");
  for (const auto& c : r.channels)
    channels.append(
        channel(c.id, c.unit, py::tuple(py::cast(ChannelShape(c.rows, c.cols))), false, false, ""));
  py::array_t<double> t(static_cast<py::ssize_t>(r.times.size()));
  std::copy(r.times.begin(), r.times.end(), t.mutable_data());
  py::array_t<double> d(
      {static_cast<py::ssize_t>(r.times.size()), static_cast<py::ssize_t>(r.values_per_sample)});
  std::copy(r.data.begin(), r.data.end(), d.mutable_data());
  return py::make_tuple(channels, t, d);
}

// Scene bytes by path, read once (ReadScene: a URDF converted to COLLADA here).
class Scenes {
 public:
  const std::string& Of(const std::string& path) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = bytes_.find(path);
    if (it == bytes_.end()) {
      try {
        it = bytes_.emplace(path, client::ReadScene(path)).first;
      } catch (const std::runtime_error& e) {
        throw client::SetupError(e.what());
      }
    }
    return it->second;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, std::string> bytes_;
};

py::tuple RunOn(ModelObject& m, const experiment::Experiment& e) {
  experiment::Recording r;
  {
    py::gil_scoped_release release;
    Scenes scenes;  // read afresh: the file as it is now
    const std::string& bytes = scenes.Of(e.scene);
    CallScope scope(kLongCallS);
    M::Recording_var idl =
        client::Call(m.ref, [&] { return m.ref.model->run_experiment(client::ToIdl(e, bytes)); });
    r = client::FromIdl(idl.in());
  }
  return RecordingTuple(r);
}

struct Pool {
  Pool(SessionHandle& s, const std::string& glob, client::ModelPool::Options options)
      : session(s), pool(client::ModelPool::Find(*s.session, glob), options) {}
  SessionHandle session;
  client::ModelPool pool;
  Scenes scenes;
};

std::unique_ptr<Pool> MakePool(SessionHandle& s, const std::string& glob, double run_timeout_s,
                               int attempts, double wait_for_model_s) {
  if (attempts < 1) throw py::value_error("attempts must be >= 1");
  client::ModelPool::Options o;
  o.run_timeout_s = run_timeout_s;
  o.attempts = attempts;
  o.wait_for_model_s = wait_for_model_s;
  auto pool = std::make_unique<Pool>(s, glob, o);
  py::gil_scoped_release release;
  CallScope scope(s.timeout_s);
  pool->pool.Refresh(false);
  return pool;
}

py::tuple PoolRun(Pool& p, const experiment::Experiment& e) {
  experiment::Recording r;
  {
    py::gil_scoped_release release;
    CallScope scope(p.session.timeout_s);
    r = p.pool.Run(e, p.scenes.Of(e.scene));
  }
  return RecordingTuple(r);
}

struct Calibration {
  Calibration(const std::string& path, Pool& pool)
      : spec(calibration::LoadSpec(path)), evaluator(spec, pool.pool) {}
  calibration::Spec spec;
  calibration::Evaluator evaluator;
};

py::dict Evaluate(Calibration& c, const std::vector<double>& values, bool keep) {
  if (values.size() != c.spec.parameters.size())
    throw py::value_error("values must have " + std::to_string(c.spec.parameters.size()) +
                          " elements (one per parameter), not " + std::to_string(values.size()));
  for (size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw py::value_error("values[" + std::to_string(i) + "] must be finite");
  calibration::Evaluation e;
  {
    py::gil_scoped_release release;
    CallScope scope(kLongCallS);
    e = c.evaluator.Evaluate(values, keep);
  }
  py::dict out;
  out["cost"] = e.cost;
  out["faulted"] = e.faulted;
  out["fault"] = e.fault;
  py::list channels, recordings;
  for (const auto& ch : e.channels)
    channels.append(py::make_tuple(ch.column, ch.weight, ch.rms, ch.range, ch.samples));
  for (const auto& r : e.recordings) recordings.append(RecordingTuple(r));
  out["channels"] = channels;
  out["recordings"] = recordings;
  return out;
}

void BindExperiment(py::module_& m) {
  py::class_<experiment::Experiment>(m, "_Experiment")
      .def_readonly("name", &experiment::Experiment::name)
      .def_readonly("scene", &experiment::Experiment::scene)
      .def_readonly("record", &experiment::Experiment::record)
      .def_readonly("every_n_steps", &experiment::Experiment::every_n_steps)
      .def_readonly("duration_s", &experiment::Experiment::duration_s)
      .def_property_readonly(
          "overrides",
          [](const experiment::Experiment& e) {
            py::dict out;
            for (const auto& o : e.overrides) out[py::str(o.id)] = o.values;
            return out;
          },
          "The parameters written before the run: {id: values}, in order (a sweep's too).")
      .def("__repr__", [](const experiment::Experiment& e) {
        return "<caliper experiment " + e.name + ": " + e.scene + ", " +
               std::to_string(e.duration_s) + " s>";
      });
  m.def("_load_experiments", &experiment::LoadFile, py::arg("path"));
  m.def("_run_on", &RunOn, py::arg("model"), py::arg("experiment"));
}

}  // namespace

void BindWork(py::module_& m) {
  BindExperiment(m);
  py::class_<Pool>(m, "_Pool")
      .def(py::init(&MakePool), py::arg("session"), py::arg("glob"), py::arg("run_timeout_s"),
           py::arg("attempts"), py::arg("wait_for_model_s"))
      .def("refresh",
           [](Pool& p) {
             py::gil_scoped_release release;
             CallScope scope(p.session.timeout_s);
             return p.pool.Refresh(true);
           })
      .def_property_readonly("size", [](Pool& p) { return p.pool.size(); })
      .def_property_readonly("available", [](Pool& p) { return p.pool.available(); })
      .def("names",
           [](Pool& p) {
             std::vector<std::string> out;
             for (size_t i = 0; i < p.pool.size(); ++i) out.push_back(p.pool.name(i));
             return out;
           })
      .def("set_on_lost",
           [](Pool& p, py::function f) {
             p.pool.on_lost = [f](const std::string& why) {
               py::gil_scoped_acquire acquire;
               f(why);
             };
           })
      .def("run", &PoolRun, py::arg("experiment"));
  py::class_<Calibration>(m, "_Calibration")
      .def(py::init<const std::string&, Pool&>(), py::arg("path"), py::arg("pool"),
           py::keep_alive<1, 3>())
      .def("parameters",
           [](Calibration& c) {
             py::list out;
             for (const auto& p : c.spec.parameters)
               out.append(py::make_tuple(p.id, p.lower, p.upper, p.log_scale));
             return out;
           })
      .def("experiments", [](Calibration& c) { return c.spec.experiments; })
      .def("evaluate", &Evaluate, py::arg("values"), py::arg("keep_recordings") = false)
      .def_property_readonly("evaluations",
                             [](Calibration& c) { return c.evaluator.evaluations(); })
      .def_property_readonly("faults", [](Calibration& c) { return c.evaluator.faults(); });
}

}  // namespace caliper::python
