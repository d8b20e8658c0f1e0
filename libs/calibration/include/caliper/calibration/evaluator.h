#pragma once
// Evaluates candidate parameters of a calibration on the Models of a session or cluster (the
// client library's ModelPool): each experiment runs on a free Model (run_experiment: a fresh load,
// bit-identical anywhere); a Model lost mid-run hands the run to another one; a physics fault
// gives a large finite cost.

#include <atomic>
#include <map>
#include <string>
#include <vector>

#include "caliper/calibration/calibration.h"
#include "caliper/client/model_pool.h"

namespace caliper::calibration {

/// The cost of a candidate whose physics faulted (NaN, explosion): far above any real fit, finite
/// so that the optimiser keeps working.
constexpr double kFaultCost = 1e3;

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
  Evaluator(const Spec& spec, client::ModelPool& pool);
  /// The candidate with parameter values (in their units); thread-safe.
  Evaluation Evaluate(const std::vector<double>& values, bool keep_recordings = false);
  /// The same from the unit search space [0, 1]^n.
  double CostOfUnit(const std::vector<double>& unit);
  std::vector<double> ValuesOf(const std::vector<double>& unit) const;
  uint64_t evaluations() const { return evaluations_; }
  uint64_t faults() const { return faults_; }

 private:
  const Spec& spec_;
  client::ModelPool& pool_;
  std::map<std::string, std::string> scenes_;  // path -> bytes
  std::atomic<uint64_t> evaluations_{0};
  std::atomic<uint64_t> faults_{0};
};

}  // namespace caliper::calibration
