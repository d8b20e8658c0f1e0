#pragma once
// One pool of Models for work spread over a session's or a cluster's Models (batch runs,
// calibration): the Models found by a glob (only Models: not the managers), new ones joining
// while the work runs, a Model lost on the way (killed, unreachable, timed out, busy with a run
// given up on) set aside and probed until it answers idle again, and runs handed to a free
// Model with retries on another when one is lost.
//
// Two ways to use it: callers that just want a run done call Run() or WithModel() from any
// number of threads (each takes a free Model for the call: calibration); callers that keep a
// thread per Model (batch) take on_joined, then model(), SetDown() and Probe() per member.

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "caliper/client/errors.h"
#include "caliper/client/model.h"
#include "caliper/client/session.h"
#include "caliper/experiment/experiment.h"
#include "caliper/model.hh"

namespace caliper::client {

/// A run could not be set up (the scene does not load, an id the scene lacks): the work cannot
/// go on, whichever Model takes it.
class SetupError : public Failure {
 public:
  using Failure::Failure;
};

class ModelPool {
 public:
  /// Lists the Models now; called again to find new ones. Exceptions count as "none found now".
  using Finder = std::function<std::vector<ModelEntry>()>;
  struct Options {
    double run_timeout_s = 3600;  ///< the longest one call to a Model may take [s]
    int attempts = 5;             ///< Models lost under one run before Run gives up
    double wait_for_model_s = 60;  ///< how long Run waits while every Model is lost [s]
    double probe_timeout_s = 1;    ///< the deadline of a probe of a lost Model [s]
  };

  ModelPool(Finder find, Options options);
  /// Finds the Models of `session` matching `glob` (FindModels: only Models).
  static Finder Find(Session& session, const std::string& glob);

  /// Finds new Models (on_joined is told of each) and, with `probe`, probes lost ones (each
  /// probe may wait Options::probe_timeout_s); returns how many can take runs.
  size_t Refresh(bool probe = true);
  /// Members found so far, lost ones included; members keep their index.
  size_t size() const;
  /// Members not set aside as lost.
  size_t available() const;

  /// Runs `e` with the scene's bytes on a free Model. A Model lost on the way is set aside and
  /// the run goes to another; after Options::attempts losses, or when no Model answers for
  /// Options::wait_for_model_s, Failure. A physics fault or a value the engine refuses:
  /// RunFailedError. A scene or id that cannot be set up: SetupError. Thread-safe.
  experiment::Recording Run(const experiment::Experiment& e, const std::string& scene_bytes);
  /// Calls `fn` with a free Model (for exports and reads), the same retries as Run: a CORBA
  /// system exception or NotAvailableError from `fn` loses the Model. Thread-safe.
  void WithModel(const std::function<void(::Caliper::Simulation::Model_ptr)>& fn);

  // per member (batch's thread per Model); `index` < size()
  const std::string& name(size_t index) const;  ///< model1@hostb
  const std::string& path(size_t index) const;  ///< hostb.host_cxt/model1.rtc
  ::Caliper::Simulation::Model_ptr model(size_t index) const;  ///< the caller owns it
  bool down(size_t index) const;
  /// Sets the member aside as lost (`why` is told to on_lost).
  void SetDown(size_t index, const std::string& why);
  /// A lost member that answers and runs nothing comes back; true when it is up.
  bool Probe(size_t index);

  /// Told of each member found, with its index (from Refresh's thread).
  std::function<void(size_t index)> on_joined;
  /// Told of each Model lost, "NAME: why" (for the console).
  std::function<void(const std::string&)> on_lost;

 private:
  struct Member {
    std::string name, path;
    ::Caliper::Simulation::Model_var model;
    bool busy = false;
    bool down = false;
  };
  size_t Acquire();
  void Release(size_t index, bool lost, const std::string& why);

  Finder find_;
  Options options_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Member> members_;  // a deque: references to members stay valid as it grows
  std::chrono::steady_clock::time_point last_refresh_;
};

}  // namespace caliper::client
