#pragma once
// The parts of an experiment run (ModelCore::RunExperiment) that need no lock, no engine build
// and no stepping: the last scene imported from bytes (batches send the same file run after
// run), the overrides, and ExperimentRunner, which checks a run before its first step, hands out
// the schedule's commands as they fall due and samples the recorded ids. The owner loads the
// scene, steps, and lets other calls in between slices.
//
// Threading: not thread-safe. ModelCore calls them with its lock (ModelCore::mutex_) held, except
// ImportCache, which only RunExperiment's thread uses.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "caliper/daq/registry.h"
#include "caliper/experiment/experiment.h"
#include "caliper/sgal/scene.h"

namespace caliper::simulation {

/// The last scene imported from bytes; see the file's comment for the threading.
class ImportCache {
 public:
  /// Imports a scene sent as the bytes of a file named `file_name` (throws what the importer does).
  using Importer =
      std::function<sgal::Scene(const std::string& file_name, const std::string& bytes)>;
  /// The scene of `bytes` named `file_name`: the last one when both are equal to the last call's
  /// (the importer is deterministic), else `import`'s, remembered. A failed import forgets the
  /// last.
  std::shared_ptr<const sgal::Scene> Get(const std::string& file_name, const std::string& bytes,
                                         const Importer& import);

 private:
  std::string name_, bytes_;                  // of the scene remembered
  std::shared_ptr<const sgal::Scene> scene_;  // null: none
};

/// Writes `experiment`'s overrides through `registry`, in order. Throws UnknownId for an id the
/// registry lacks and InvalidValue for a write it refuses, both naming the experiment.
void ApplyOverrides(const experiment::Experiment& experiment, daq::Registry& registry);

/// One experiment run's schedule and recording; see the file's comment for the threading.
class ExperimentRunner {
 public:
  /// Checks the run before any step: its recorded ids (resolved once in `registry`, which must
  /// outlive the run unchanged, as must `experiment`), its schedule's actuators among `actuators`,
  /// its step count at `time_step` [s] against `max_steps` and its recording's size against
  /// `max_bytes`. Throws UnknownId or InvalidValue naming the experiment and what is wrong.
  ExperimentRunner(const experiment::Experiment& experiment, const daq::Registry& registry,
                   const std::vector<sgal::Actuator>& actuators, double time_step,
                   uint64_t max_steps, size_t max_bytes);
  ExperimentRunner(const ExperimentRunner&) = delete;
  ExperimentRunner& operator=(const ExperimentRunner&) = delete;

  /// Steps the run takes.
  uint64_t steps() const { return steps_; }
  /// Appends to `pending` the scheduled commands due by the start of the step at simulated time
  /// `time` [s] (a part per billion of a step counts as due) and not handed out yet, in order.
  void TakeDueCommands(double time, std::vector<std::pair<std::string, double>>* pending);
  /// Whether a sample follows step `k` (1 for the first step).
  bool SampleDue(uint64_t k) const { return k % every_n_steps_ == 0; }
  /// Reads every recorded id into a sample at simulated time `time` [s].
  void Sample(double time);
  /// The channels and samples so far.
  experiment::Recording& recording() { return recording_; }

 private:
  const daq::Registry& registry_;
  const std::vector<experiment::Command>& schedule_;
  uint32_t every_n_steps_ = 1;  // [steps] between samples
  double time_step_ = 0;        // [s]
  uint64_t steps_ = 0;
  size_t next_command_ = 0;                              // in schedule_
  std::vector<std::pair<daq::Handle, size_t>> columns_;  // handle, first value in a sample
  experiment::Recording recording_;
};

}  // namespace caliper::simulation
