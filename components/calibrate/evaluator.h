#pragma once
// Evaluates candidate parameters of a calibration on the Models of a session or cluster: each
// experiment runs on a free Model (run_experiment: a fresh load, bit-identical anywhere); a Model
// lost mid-run hands the run to another one; a physics fault gives a large finite cost.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "calibration.h"
#include "caliper/model.hh"

namespace caliper::calibrate {

/// The cost of a candidate whose physics faulted (NaN, explosion): far above any real fit, finite
/// so that the optimiser keeps working.
constexpr double kFaultCost = 1e3;

/// A run could not be set up (bad id, scene not loadable): calibrating cannot go on.
class SetupError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The Models found in the naming service, each used by one run at a time.
class ModelPool {
 public:
  /// `find` lists the Models now (name, naming path, object); called again to find new ones.
  using Finder = std::function<std::vector<std::tuple<std::string, std::string, CORBA::Object_var>>()>;
  ModelPool(Finder find, double run_timeout_s);

  /// Finds new Models and probes lost ones; returns how many can take runs.
  size_t Refresh();
  size_t size() const;

  /// Runs `e` on a free Model. A Model lost on the way (killed, unreachable, timed out) is set
  /// aside and the run goes to another; after `attempts` losses, or when no Model answers for
  /// `wait_s`, std::runtime_error. A physics fault: RunFault. A bad set-up: SetupError.
  experiment::Recording Run(const experiment::Experiment& e, const std::string& scene_bytes);
  /// Calls `fn` with a free Model (for exports and reads); the same retries as Run.
  void WithModel(const std::function<void(::Caliper::Simulation::Model_ptr)>& fn);

  /// Called with each lost Model's name and reason (for the console).
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
  double run_timeout_s_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Member> members_;
  std::chrono::steady_clock::time_point last_refresh_;
};

/// A Model that cannot take a run now (still busy with one given up on, shutting down).
class Busy : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run whose physics faulted; the message is the Model's report.
class RunFault : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One candidate's outcome: its cost and, when asked for, the recordings.
struct Evaluation {
  double cost = 0;
  bool faulted = false;
  std::string fault;
  std::vector<experiment::Recording> recordings;  // per experiment
  std::vector<ChannelCost> channels;
};

class Evaluator {
 public:
  Evaluator(const Spec& spec, ModelPool& pool);
  /// The candidate with parameter values (in their units); thread-safe.
  Evaluation Evaluate(const std::vector<double>& values, bool keep_recordings = false);
  /// The same from the unit search space [0, 1]^n.
  double CostOfUnit(const std::vector<double>& unit);
  std::vector<double> ValuesOf(const std::vector<double>& unit) const;
  uint64_t evaluations() const { return evaluations_; }
  uint64_t faults() const { return faults_; }

 private:
  const Spec& spec_;
  ModelPool& pool_;
  std::map<std::string, std::string> scenes_;  // path -> bytes
  std::atomic<uint64_t> evaluations_{0};
  std::atomic<uint64_t> faults_{0};
};

}  // namespace caliper::calibrate
