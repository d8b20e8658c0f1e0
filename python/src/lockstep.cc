// caliper._caliper._Lockstep: one lock-step cycle (set the commands, step N, read the observed
// channels: the Model's control_cycle, one round trip) on several Models at once, for the
// environments (caliper.env). The cycles run on
// threads of this module with the GIL released, one per Model after the first, which the
// calling thread runs itself; Python is touched only before and after.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <thread>

#include "model_object.h"

namespace caliper::python {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
namespace S = ::Caliper::Scene;

namespace {

class Lockstep {
 public:
  Lockstep(std::vector<std::shared_ptr<ModelObject>> models,
           const std::vector<std::string>& actuators, const py::object& ids) {
    if (models.empty()) throw py::value_error("models must name at least one Model");
    if (actuators.empty()) throw py::value_error("actuators must name at least one actuator");
    const std::vector<std::string> observed = IdList(ids, "observations");
    for (auto& m : models) {
      Lane lane;
      lane.model = m;
      lane.commands.length(static_cast<CORBA::ULong>(actuators.size()));
      for (size_t a = 0; a < actuators.size(); ++a)
        lane.commands[static_cast<CORBA::ULong>(a)].actuator = actuators[a].c_str();
      lane.ids.length(static_cast<CORBA::ULong>(observed.size()));
      for (size_t i = 0; i < observed.size(); ++i)
        lane.ids[static_cast<CORBA::ULong>(i)] = observed[i].c_str();
      lanes_.push_back(std::move(lane));
    }
    // looking before sleeping pays only while every lane has a core to itself
    spin_ = lanes_.size() <= std::max(1u, std::thread::hardware_concurrency())
                ? kSpin
                : std::chrono::microseconds(0);
    for (size_t i = 1; i < lanes_.size(); ++i) workers_.emplace_back([this, i] { Work(i); });
  }

  ~Lockstep() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    py::gil_scoped_release release;
    for (auto& w : workers_) w.join();
  }

  // commands: Models x actuators [their unit]; returns Models x observed values
  py::array_t<double> Step(
      const py::array_t<double, py::array::c_style | py::array::forcecast>& commands,
      uint32_t frames) {
    const size_t n = lanes_.size(), a = lanes_[0].commands.length();
    if (commands.ndim() != 2 || static_cast<size_t>(commands.shape(0)) != n ||
        static_cast<size_t>(commands.shape(1)) != a)
      throw py::value_error("commands must have shape (" + std::to_string(n) + ", " +
                            std::to_string(a) + ")");
    if (frames < 1) throw py::value_error("frames must be >= 1");
    for (size_t i = 0; i < n; ++i)
      for (size_t k = 0; k < a; ++k) {
        const double v = commands.at(i, k);
        if (!std::isfinite(v)) throw py::value_error("commands must be finite");
        lanes_[i].commands[static_cast<CORBA::ULong>(k)].value = v;
      }
    {
      py::gil_scoped_release release;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        frames_ = frames;
        pending_ = n - 1;
        ++generation_;
      }
      wake_.notify_all();
      Cycle(lanes_[0]);
      // the other lanes end within a few hundred microseconds of this one: look before sleeping
      // (a wake-up across virtual CPUs costs more than the wait)
      SpinUntil([&] { return pending_.load() == 0; }, spin_);
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, [&] { return pending_.load() == 0; });
    }
    for (auto& lane : lanes_)
      if (lane.error) std::rethrow_exception(std::exchange(lane.error, nullptr));
    const size_t width = lanes_[0].values.size();
    py::array_t<double> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(width)});
    for (size_t i = 0; i < n; ++i) {
      if (lanes_[i].values.size() != width)
        throw py::value_error("the Models observe different numbers of values");
      std::copy(lanes_[i].values.begin(), lanes_[i].values.end(), out.mutable_data(i, 0));
    }
    return out;
  }

 private:
  struct Lane {
    std::shared_ptr<ModelObject> model;
    M::CommandSeq commands;
    S::StringSeq ids;
    std::vector<double> values;
    std::exception_ptr error;
  };

  // one cycle on one Model, without the GIL; errors are kept for the caller
  void Cycle(Lane& lane) {
    try {
      ModelObject& m = *lane.model;
      M::CycleResult_var cycle;
      {
        CallScope scope(kLongCallS);
        cycle = client::Call(
            m.ref, [&] { return m.ref.model->control_cycle(lane.commands, frames_, lane.ids); });
      }
      const CORBA::ULong ran = cycle->steps;
      if (ran < frames_) {
        CallScope scope(m.s.timeout_s);
        M::SimulationStatus_var s = client::Call(m.ref, [&] { return m.ref.model->status(); });
        if (s->state == M::FAULTED)
          throw client::RunFailedError(m.ref.name + ": the simulation faulted after " +
                                       std::to_string(ran) + " of " + std::to_string(frames_) +
                                       " steps: " + s->last_error.in());
      }
      const D::ValueSeq& values = cycle->values;
      lane.values.clear();
      for (CORBA::ULong i = 0; i < values.length(); ++i)
        lane.values.insert(lane.values.end(), values[i].data.get_buffer(),
                           values[i].data.get_buffer() + values[i].data.length());
    } catch (...) {
      lane.error = std::current_exception();
    }
  }

  void Work(size_t index) {
    uint64_t seen = 0;
    while (true) {
      // the next cycle usually comes after the caller's Python work on this one: look first
      SpinUntil([&] { return quit_.load() || generation_.load() != seen; }, spin_);
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return quit_.load() || generation_.load() != seen; });
        if (quit_) return;
        seen = generation_;
      }
      Cycle(lanes_[index]);
      std::lock_guard<std::mutex> lock(mutex_);
      if (--pending_ == 0) done_.notify_all();
    }
  }

  // Checks `ready` for up to `spin`, yielding the CPU between looks.
  template <class Ready>
  static void SpinUntil(Ready ready, std::chrono::microseconds spin) {
    const auto until = std::chrono::steady_clock::now() + spin;
    while (!ready() && std::chrono::steady_clock::now() < until) std::this_thread::yield();
  }
  static constexpr std::chrono::microseconds kSpin{300};

  std::vector<Lane> lanes_;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::atomic<uint64_t> generation_{0};
  std::atomic<size_t> pending_{0};
  CORBA::ULong frames_ = 1;
  std::atomic<bool> quit_{false};
  std::chrono::microseconds spin_{0};
};

}  // namespace

void BindLockstep(py::module_& m) {
  py::class_<Lockstep>(m, "_Lockstep")
      .def(py::init<std::vector<std::shared_ptr<ModelObject>>, const std::vector<std::string>&,
                    const py::object&>(),
           py::arg("models"), py::arg("actuators"), py::arg("observations"))
      .def("step", &Lockstep::Step, py::arg("commands"), py::arg("frames"));
}

}  // namespace caliper::python
