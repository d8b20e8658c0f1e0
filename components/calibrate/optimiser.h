#pragma once
// The search: pagmo's evolution strategies (cmaes or xnes) on an archipelago of one thread island
// per Model. pagmo 2.18's cmaes takes no batch fitness evaluator, so parallel evaluation comes
// from the islands: each evolves its own population, and its evaluations take whichever Model is
// free. With `memory` on, one evolve() is one generation and the adaptation (step size,
// covariance) carries on, so progress, Ctrl-C and checkpoints fall between generations.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "caliper/calibration/calibration.h"

namespace caliper::calibration {

class Evaluator;

/// Where the search stands after a generation.
struct Progress {
  unsigned generation = 0;  // completed
  uint64_t evaluations = 0;
  double best_cost = 0;           // the best found so far
  std::vector<double> best_unit;  // its candidate in [0, 1]^n
  double spread = 0;              // mean standard deviation of the populations in [0, 1]
  std::vector<std::pair<uint64_t, double>> history;  // (evaluations, best cost) per generation
  unsigned restarts = 0;                             // IPOP restarts so far
  unsigned population = 0;                           // per island, now
  unsigned restart_generation = 0;  // the generation the current populations started at
  /// The best cost per generation since the last restart (the start of it first).
  std::vector<double> CostsSinceRestart() const;
};

class Search {
 public:
  /// Islands start around `start_unit` (cost `start_cost`), spread by the optimiser's sigma0.
  Search(const Spec& spec, Evaluator& evaluator, unsigned islands,
         const std::vector<double>& start_unit, double start_cost);
  /// From a checkpoint written by Save; std::runtime_error when it does not fit the spec.
  Search(const Spec& spec, Evaluator& evaluator, const std::string& checkpoint);
  ~Search();

  /// Runs one generation on every island; `interrupted` is polled while they work (the
  /// generation still finishes). Returns false when it was interrupted.
  bool Generation(const std::function<bool()>& interrupted);
  const Progress& progress() const { return progress_; }
  unsigned islands() const;
  /// IPOP: new populations twice as large, the first island around the best so far, the
  /// others from random points of the box (seeded), the step size back to sigma0.
  void Restart();
  /// Everything needed to go on: algorithms with their adapted state, populations, progress
  /// (Boost.Serialization text archive, written whole or not at all).
  void Save(const std::string& path) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Progress progress_;
  void Measure();
  void Populate(const std::vector<double>& start_unit, double start_cost, bool random_others);
};

}  // namespace caliper::calibration
