#include "caliper/client/model_pool.h"

#include <algorithm>

#include "caliper/client/experiments.h"
#include "caliper/logging/log.h"
#include "caliper/rtc/client_orb.h"
#include "caliper/rtc/naming.h"

namespace caliper::client {

namespace M = ::Caliper::Simulation;
namespace D = ::Caliper::Daq;
using Clock = std::chrono::steady_clock;

namespace {

CORBA::ULong Ms(double seconds) { return static_cast<CORBA::ULong>(seconds * 1000); }

}  // namespace

ModelPool::ModelPool(Finder find, Options options)
    : find_(std::move(find)), options_(options) {}

ModelPool::Finder ModelPool::Find(Session& session, const std::string& glob) {
  return [&session, glob] {
    CosNaming::NamingContext_var root = session.Root();
    return FindModels(root, glob);
  };
}

size_t ModelPool::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return members_.size();
}

size_t ModelPool::available() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<size_t>(
      std::count_if(members_.begin(), members_.end(), [](const Member& m) { return !m.down; }));
}

size_t ModelPool::Refresh(bool probe_lost) {
  std::vector<ModelEntry> found;
  try {
    found = find_();
  } catch (const std::exception&) {
  } catch (const CORBA::Exception&) {
  }
  std::vector<size_t> joined, probe;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last_refresh_ = Clock::now();
    for (auto& e : found) {
      auto known = std::find_if(members_.begin(), members_.end(),
                                [&](const Member& m) { return m.path == e.path; });
      if (known == members_.end()) {
        Member m;
        m.name = e.name;
        m.path = e.path;
        m.model = M::Model::_unchecked_narrow(e.object);
        members_.push_back(std::move(m));
        joined.push_back(members_.size() - 1);
      } else if (known->down && !known->busy && !e.object->_is_equivalent(known->model)) {
        known->model = M::Model::_unchecked_narrow(e.object);  // a new process under the name
      }
    }
    for (size_t i = 0; probe_lost && i < members_.size(); ++i)
      if (members_[i].down && !members_[i].busy) probe.push_back(i);
  }
  for (size_t index : joined)
    if (on_joined) on_joined(index);
  // lost Models that answer again come back (a link that was down)
  for (size_t index : probe) Probe(index);
  std::lock_guard<std::mutex> lock(mutex_);
  changed_.notify_all();
  return static_cast<size_t>(
      std::count_if(members_.begin(), members_.end(), [](const Member& m) { return !m.down; }));
}

const std::string& ModelPool::name(size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return members_.at(index).name;
}

const std::string& ModelPool::path(size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return members_.at(index).path;
}

M::Model_ptr ModelPool::model(size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return M::Model::_duplicate(members_.at(index).model);
}

bool ModelPool::down(size_t index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return members_.at(index).down;
}

void ModelPool::SetDown(size_t index, const std::string& why) {
  std::string name;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    members_.at(index).down = true;
    name = members_[index].name;
  }
  if (on_lost) on_lost(name + ": " + why);
}

bool ModelPool::Probe(size_t index) {
  M::Model_var m = model(index);
  try {
    omniORB::setClientThreadCallTimeout(Ms(options_.probe_timeout_s));
    M::SimulationStatus_var s = m->status();
    if (s->state == M::RUNNING) return false;  // still busy with a run given up on
    std::lock_guard<std::mutex> lock(mutex_);
    members_[index].down = false;
    changed_.notify_all();
    return true;
  } catch (const CORBA::Exception&) {
    return false;
  }
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
      if (std::chrono::duration<double>(Clock::now() - begin).count() >
          options_.wait_for_model_s)
        throw Failure("no Model answered for " +
                      std::to_string(static_cast<int>(options_.wait_for_model_s)) +
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
    logging::Get("client").warn("%s lost (%s): its run goes to another Model", name.c_str(),
                                why.c_str());
    if (on_lost) on_lost(name + ": " + why);
  }
}

void ModelPool::WithModel(const std::function<void(M::Model_ptr)>& fn) {
  rtc::OmniThread omni;
  std::string last;
  for (int attempt = 0; attempt < options_.attempts; ++attempt) {
    const size_t index = Acquire();
    M::Model_var m = model(index);
    try {
      omniORB::setClientThreadCallTimeout(Ms(options_.run_timeout_s));
      fn(m);
      Release(index, false, "");
      return;
    } catch (const CORBA::SystemException& e) {
      last = rtc::Describe(e);
      Release(index, true, last);
    } catch (const NotAvailableError& e) {
      last = e.what();
      Release(index, true, last);
    } catch (...) {
      Release(index, false, "");
      throw;
    }
  }
  throw Failure("a run was lost " + std::to_string(options_.attempts) + " times (last: " + last +
                ")");
}

experiment::Recording ModelPool::Run(const experiment::Experiment& e, const std::string& bytes) {
  const M::Experiment idl = ToIdl(e, bytes);
  experiment::Recording out;
  WithModel([&](M::Model_ptr m) {
    try {
      M::Recording_var r = m->run_experiment(idl);
      out = FromIdl(r.in());
    } catch (const M::RunFailed& f) {
      throw RunFailedError(f.reason.in());
    } catch (const M::LoadFailed& f) {
      throw SetupError(f.reason.in());
    } catch (const D::UnknownId& f) {
      throw SetupError(f.reason.in());
    } catch (const D::InvalidParameter& f) {
      // a value the engine refuses (e.g. out of its range): like a fault, a bad candidate
      throw RunFailedError(f.reason.in());
    } catch (const M::NotAvailable& f) {
      // busy with a run given up on earlier (or shutting down): another Model takes this one
      throw NotAvailableError(f.reason.in());
    }
  });
  return out;
}

}  // namespace caliper::client
