#include "evaluator.h"

#include <cmath>
#include <thread>

#include "caliper/logging/log.h"
#include "caliper/rtc/naming.h"
#include "model_runs.h"

namespace caliper::calibrate {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
using Clock = std::chrono::steady_clock;

namespace {
constexpr int kAttempts = 5;
constexpr double kWaitForModelS = 60;
}  // namespace

ModelPool::ModelPool(Finder find, double run_timeout_s)
    : find_(std::move(find)), run_timeout_s_(run_timeout_s) {}

size_t ModelPool::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return members_.size();
}

size_t ModelPool::Refresh() {
  std::vector<std::tuple<std::string, std::string, CORBA::Object_var>> found;
  try {
    found = find_();
  } catch (const std::exception&) {
  } catch (const CORBA::Exception&) {
  }
  // lost Models that answer again come back (a link that was down)
  std::vector<std::pair<size_t, M::Model_var>> probe;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last_refresh_ = Clock::now();
    for (auto& [name, path, object] : found) {
      auto known = std::find_if(members_.begin(), members_.end(),
                                [&](const Member& m) { return m.path == path; });
      if (known == members_.end()) {
        Member m;
        m.name = name;
        m.path = path;
        m.model = M::Model::_unchecked_narrow(object);
        members_.push_back(std::move(m));
      } else if (known->down && !known->busy) {
        known->model = M::Model::_unchecked_narrow(object);  // maybe a new process
      }
    }
    for (size_t i = 0; i < members_.size(); ++i)
      if (members_[i].down && !members_[i].busy)
        probe.emplace_back(i, M::Model::_duplicate(members_[i].model));
  }
  for (auto& [index, model] : probe) {
    try {
      omniORB::setClientThreadCallTimeout(1000);
      M::SimulationStatus_var s = model->status();
      if (s->state == M::RUNNING) continue;  // still busy with a run given up on
      std::lock_guard<std::mutex> lock(mutex_);
      members_[index].down = false;
    } catch (const CORBA::Exception&) {
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  changed_.notify_all();
  return static_cast<size_t>(std::count_if(members_.begin(), members_.end(),
                                           [](const Member& m) { return !m.down; }));
}

size_t ModelPool::Acquire() {
  const auto begin = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    for (size_t i = 0; i < members_.size(); ++i)
      if (!members_[i].busy && !members_[i].down) {
        members_[i].busy = true;
        return i;
      }
    const bool any_up = std::any_of(members_.begin(), members_.end(),
                                    [](const Member& m) { return !m.down; });
    if (!any_up) {
      if (std::chrono::duration<double>(Clock::now() - begin).count() > kWaitForModelS)
        throw std::runtime_error("no Model answered for " + std::to_string(int(kWaitForModelS)) +
                                 " s (all lost); start some (caliper-ctl create) and --resume");
      if (Clock::now() - last_refresh_ > std::chrono::seconds(1)) {
        lock.unlock();
        Refresh();
        lock.lock();
        continue;
      }
    }
    changed_.wait_for(lock, std::chrono::milliseconds(200));
  }
}

void ModelPool::Release(size_t index, bool lost, const std::string& why) {
  std::string name;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    members_[index].busy = false;
    members_[index].down = members_[index].down || lost;
    name = members_[index].name;
    changed_.notify_all();
  }
  if (lost) {
    logging::Get("calibrate").warn("%s lost (%s): its run goes to another Model", name.c_str(),
                                   why.c_str());
    if (on_lost) on_lost(name + ": " + why);
  }
}

void ModelPool::WithModel(const std::function<void(M::Model_ptr)>& fn) {
  ctl::OmniThread omni;
  std::string last;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const size_t index = Acquire();
    M::Model_var model;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      model = M::Model::_duplicate(members_[index].model);
    }
    try {
      omniORB::setClientThreadCallTimeout(static_cast<CORBA::ULong>(run_timeout_s_ * 1000));
      fn(model);
      Release(index, false, "");
      return;
    } catch (const CORBA::SystemException& e) {
      last = rtc::Describe(e);
      Release(index, true, last);
    } catch (const Busy& e) {
      last = e.what();
      Release(index, true, last);
    } catch (...) {
      Release(index, false, "");
      throw;
    }
  }
  throw std::runtime_error("a run was lost " + std::to_string(kAttempts) +
                           " times (last: " + last + ")");
}

experiment::Recording ModelPool::Run(const experiment::Experiment& e, const std::string& bytes) {
  const M::Experiment idl = ctl::ToIdl(e, bytes);
  experiment::Recording out;
  WithModel([&](M::Model_ptr model) {
    try {
      M::Recording_var r = model->run_experiment(idl);
      out = ctl::FromIdl(r.in());
    } catch (const M::RunFailed& f) {
      throw RunFault(f.reason.in());
    } catch (const M::LoadFailed& f) {
      throw SetupError(f.reason.in());
    } catch (const D::UnknownId& f) {
      throw SetupError(f.reason.in());
    } catch (const D::InvalidParameter& f) {
      // a value the engine refuses (e.g. out of its range): like a fault, a bad candidate
      throw RunFault(f.reason.in());
    } catch (const M::NotAvailable& f) {
      // busy with a run given up on earlier (or shutting down): another Model takes this one
      throw Busy(f.reason.in());
    }
  });
  return out;
}

Evaluator::Evaluator(const Spec& spec, ModelPool& pool) : spec_(spec), pool_(pool) {
  for (const auto& e : spec.experiments)
    if (!scenes_.count(e.scene)) scenes_[e.scene] = ctl::ReadScene(e.scene);
}

std::vector<double> Evaluator::ValuesOf(const std::vector<double>& unit) const {
  std::vector<double> values;
  for (size_t i = 0; i < spec_.parameters.size(); ++i)
    values.push_back(spec_.parameters[i].FromUnit(unit[i]));
  return values;
}

Evaluation Evaluator::Evaluate(const std::vector<double>& values, bool keep_recordings) {
  Evaluation out;
  ++evaluations_;
  for (size_t i = 0; i < spec_.experiments.size(); ++i) {
    const auto e = WithParameters(spec_.experiments[i], spec_.parameters, values);
    try {
      experiment::Recording r = pool_.Run(e, scenes_.at(e.scene));
      const auto channels = CompareRecording(r, spec_.measured[i], spec_.channels);
      out.channels.insert(out.channels.end(), channels.begin(), channels.end());
      if (keep_recordings) out.recordings.push_back(std::move(r));
    } catch (const RunFault& fault) {
      ++faults_;
      out.faulted = true;
      out.fault = fault.what();
      out.cost = kFaultCost;
      logging::Get("calibrate").warn("candidate faulted, cost %g: %s", kFaultCost, fault.what());
      return out;
    }
  }
  out.cost = Cost(out.channels);
  if (!std::isfinite(out.cost)) {
    // a simulation that ran but gave NaN or infinity is as bad as one that faulted
    ++faults_;
    out.faulted = true;
    out.fault = "the simulated channels are not finite";
    out.cost = kFaultCost;
  }
  return out;
}

double Evaluator::CostOfUnit(const std::vector<double>& unit) {
  return Evaluate(ValuesOf(unit)).cost;
}

}  // namespace caliper::calibrate
