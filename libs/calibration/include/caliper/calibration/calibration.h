#pragma once
// What a calibration is, without CORBA, Qt or an optimiser: the parameters to fit with their
// bounds and scaling, the experiments (libs/experiment) and what the real robot measured in
// each, and the cost of a simulated recording against the measurements.
//
// Calibration files are JSON (Boost.PropertyTree), paths relative to the file:
//   {
//     "experiments": "runs.json",        experiment file (libs/experiment): scene, schedules,
//                                        recorded ids, durations
//     "measured": {"steps": "steps.csv"} per experiment: CSV with `time [s]` and columns named
//                                        like recordings (`id [unit]`, `id[k] [unit]`); any rate
//     "parameters": [{"id": "arm.elbow_flexor.stiffness", "lower": 1500, "upper": 6000,
//                     "scale": "log"}],  linear (default) or log
//     "channels": [{"id": "arm.elbow.position", "weight": 2, "window_s": [0.5, 4]}],
//                                        optional: weights and time windows (default 1, all)
//     "optimiser": {"algorithm": "cmaes", "generations": 60, "population": 10, "sigma0": 0.25,
//                   "window": 20, "cost_tolerance": 1e-6, "step_tolerance": 1e-4,
//                   "target_cost": 0, "restarts": 2},  stopping rules, IPOP restarts
//     "refinement": {"iterations": 30, "jacobian": "central", "step": 1e-3},  LM (Ceres);
//                                        "iterations": 0 turns it off
//     "uncertainty": {"max_relative_interval": 0.1, "max_correlation": 0.95},  warnings
//     "held_out": ["gentle"],            experiments not fitted, their cost reported
//     "seed": 7
//   }
// Parameter ids name a scene parameter (set before each run), or one of the recording's
// timing: "time_shift" (the measurements' clock minus the simulation's [s]),
// "sensor_delay:CHANNEL" (a measured channel lags the truth by it [s]) and
// "command_delay:ACTUATOR" (the actuator acts on a command this much later [s]).

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/experiment/experiment.h"

namespace caliper::calibration {

/// A file or value that cannot be used: the message names the file and what is wrong.
class SpecError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ParameterKind {
  kScene,         // a scene parameter (an override before the run)
  kTimeShift,     // every measured time is shifted by it [s]
  kSensorDelay,   // one measured channel lags by it [s]
  kCommandDelay,  // one actuator's commands arrive late by it [s]
};

struct Parameter {
  std::string id;
  double lower = 0, upper = 0;  // bounds, in the parameter's unit
  bool log_scale = false;       // search log(value) uniformly
  ParameterKind kind = ParameterKind::kScene;
  std::string target;     // the channel or actuator of a delay
  std::string unit;       // a scene parameter's, as its Model gives it
  double resolution = 0;  // the smallest change that acts (a command delay: one time step)
  /// The unit shown for it: "s" for the timing ones, the scene's otherwise.
  std::string Unit() const { return kind == ParameterKind::kScene ? unit : "s"; }
  /// The value at `u` in [0, 1] of the search space, and back.
  double FromUnit(double u) const;
  double ToUnit(double value) const;
};

/// A measured table: times [s] and named columns (`id` or `id[k]`, unit stripped).
struct Measured {
  std::string file;
  std::vector<double> times;
  std::vector<std::string> columns;
  std::vector<std::string> units;
  std::vector<std::vector<double>> values;  // per column, per time
  /// Linear interpolation of column `c` at `t` (t within the table's time span).
  double At(size_t c, double t) const;
};

struct ChannelWeight {
  double weight = 1;
  double from_s = -1e300, to_s = 1e300;  // time window [s]
};

struct Optimiser {
  std::string algorithm = "cmaes";  // cmaes or xnes (pagmo)
  unsigned generations = 40;
  unsigned population = 10;  // per island
  double sigma0 = 0.25;      // initial step in the unit search space
  // stopping: whichever comes first, beside the budget of generations
  unsigned window = 20;          // generations over which the cost's change is judged
  double cost_tolerance = 1e-6;  // relative change of the best cost over the window
  double step_tolerance = 1e-4;  // the populations' spread in the unit box
  double target_cost = 0;        // stop when the best cost is this low (0: no target)
  unsigned restarts = 2;         // IPOP: a stalled search restarts with twice the population
};

/// The local refinement after the global search: Levenberg-Marquardt on the residuals.
struct Refinement {
  unsigned iterations = 30;  // 0: no refinement
  bool central = true;       // central or forward finite differences
  double step = 1e-3;        // in the unit search space
};

struct UncertaintyOptions {
  double max_relative_interval = 0.1;  // warn when a 95 % half-width exceeds this fraction
  double max_correlation = 0.95;       // warn above this |correlation|
};

struct Spec {
  std::string file;
  std::vector<experiment::Experiment> experiments;
  std::vector<Measured> measured;  // one per experiment, same order
  std::vector<bool> held_out;      // per experiment: not fitted, its cost reported
  std::vector<Parameter> parameters;
  std::map<std::string, ChannelWeight> channels;  // by column name; absent: weight 1, all times
  Optimiser optimiser;
  Refinement refinement;
  UncertaintyOptions uncertainty;
  uint64_t seed = 1;
  size_t Fitted() const;  // experiments that are fitted
};

/// Reads a calibration file and the files it names; throws SpecError naming the file.
Spec LoadSpec(const std::string& path);

/// A measured CSV: a header `time [s],name [unit],...` then numbers; throws SpecError.
Measured LoadMeasured(const std::string& path);

/// The column names of a recording of `channels`: `id` for a scalar, `id[k]` for an element
/// (row-major), as in recording CSVs.
std::vector<std::string> ColumnNames(const std::vector<experiment::Channel>& channels);

/// What one experiment contributes to the cost: per compared column, the RMS of (simulated -
/// measured) over the measured range of that column, at the simulated sample times inside the
/// measured time span and the column's window.
struct ChannelCost {
  std::string column;
  double weight = 1;
  double rms = 0;    // [column unit]
  double range = 1;  // measured max - min [column unit]
  size_t samples = 0;
  std::string unit;       // the measured column's
  size_t experiment = 0;  // index in Spec::experiments (set by the evaluator)
};
/// The timing parameters of a candidate: the measurements' time shift, and a delay per
/// measured column (by name).
struct Timing {
  double shift_s = 0;
  std::map<std::string, double> sensor_delay_s;
};
Timing TimingOf(const std::vector<Parameter>& parameters, const std::vector<double>& values);

/// `residuals`, when given, receives (simulated - measured) of every compared sample, channel by
/// channel in the order of the result. The simulated sample at t is compared with the
/// measurement at t + shift + the column's delay; which samples count depends on t only.
std::vector<ChannelCost> CompareRecording(const experiment::Recording& simulated,
                                          const Measured& measured,
                                          const std::map<std::string, ChannelWeight>& weights,
                                          const Timing& timing = {},
                                          std::vector<double>* residuals = nullptr);

/// The weighted mean of (rms / range)^2 over every channel of every experiment, square-rooted:
/// 0 for a perfect fit, about 1 for an error as large as the signal. SpecError when no channel
/// of the recordings is in the measurements.
double Cost(const std::vector<ChannelCost>& channels);

/// The experiment with the scene parameters' values as overrides (after its own) and the
/// command delays applied to its schedule.
experiment::Experiment WithParameters(const experiment::Experiment& e,
                                      const std::vector<Parameter>& parameters,
                                      const std::vector<double>& values);

}  // namespace caliper::calibration
