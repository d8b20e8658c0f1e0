#pragma once
// Evaluates candidate parameters of a calibration on the Models of a session or cluster (the
// client library's ModelPool): each experiment runs on a free Model (run_experiment: a fresh load,
// bit-identical anywhere); a Model lost mid-run hands the run to another one; a physics fault
// gives a large finite cost.

#include <atomic>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "caliper/calibration/analysis.h"
#include "caliper/calibration/calibration.h"
#include "caliper/client/model_pool.h"

namespace caliper::calibration {

/// The cost of a candidate whose physics faulted (NaN, explosion): far above any real fit, finite
/// so that the optimiser keeps working.
constexpr double kFaultCost = 1e3;

/// One candidate's outcome: its cost and, when asked for, the recordings and residuals.
struct Evaluation {
  double cost = 0;            // of the fitted experiments
  double held_out_cost = -1;  // of the held-out ones, when evaluated (-1: not)
  bool faulted = false;
  std::string fault;
  std::vector<experiment::Recording> recordings;  // per experiment evaluated, in file order
  std::vector<size_t> recorded;                   // their experiment indices
  std::vector<ChannelCost> channels;              // fitted experiments' channels
  std::vector<ChannelCost> held_out_channels;
  std::vector<double> residuals;      // fitted: simulated - measured, per sample
  std::vector<ResidualBlock> blocks;  // their channels
};

struct EvaluateOptions {
  bool keep_recordings = false;
  bool residuals = false;
  bool held_out = false;  // also run the held-out experiments
};

class Evaluator {
 public:
  Evaluator(const Spec& spec, client::ModelPool& pool);
  /// The candidate with parameter values (in their units); thread-safe.
  Evaluation Evaluate(const std::vector<double>& values, bool keep_recordings = false);
  Evaluation Evaluate(const std::vector<double>& values, const EvaluateOptions& options);
  /// Several candidates at once, each on a free Model (a thread per candidate, at most one per
  /// Model of the pool at a time).
  std::vector<Evaluation> EvaluateMany(const std::vector<std::vector<double>>& values,
                                       const EvaluateOptions& options);
  /// The residuals of unit points, in parallel; nullopt for a faulted one. Weighted: their
  /// squares sum to the cost squared (the refinement's batch); else raw, simulated - measured
  /// in each channel's unit (the uncertainty's Jacobian).
  std::vector<std::optional<std::vector<double>>> Residuals(
      const std::vector<std::vector<double>>& units, bool weighted);
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
