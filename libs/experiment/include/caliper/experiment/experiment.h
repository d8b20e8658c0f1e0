#pragma once
// An experiment: a scene, parameter overrides, a command schedule, the ids to record and a
// duration. The one unit that batch runs, calibration and recordings share; no CORBA here.
//
// Experiment files are JSON (read with Boost.PropertyTree). The top level holds defaults; each
// entry of "experiments" adds to or replaces them; without "experiments" the file is one run.
//   {
//     "scene": "arm.dae",                      scene file, relative to the experiment file
//     "duration_s": 2.0,                       simulated time [s]
//     "every_n_steps": 10,                     one sample every N steps (default 1)
//     "record": ["arm.elbow.position"],        ids sampled (DAQ ids, `caliper-ctl params`)
//     "set": {"arm.forearm.mass": 0.4,         parameter overrides: a number or a list
//             "arm.gravity": [0, 0, -9.81]},
//     "commands": [[0.0, "elbow_flexor", 6]],  [time s, actuator, value] from that time on
//     "commands_csv": "schedule.csv",          or a CSV: time [s],actuator,value
//     "sweep": {"arm.forearm.mass": [0.3, 0.5]},  one run per combination of the values
//     "experiments": [{"name": "light", "set": {...}}, ...]
//   }

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::experiment {

/// A file or value that cannot be read: the message names the file, the experiment and the key.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// From `time_s` on, `actuator`'s command is `value` (in its command unit).
struct Command {
  double time_s = 0;  // [s]
  std::string actuator;
  double value = 0;
};

/// A parameter written before the run: one value per element of its shape.
struct Override {
  std::string id;
  std::vector<double> values;
};

struct Experiment {
  std::string name;                  // unique in a batch; letters, digits, . _ -
  std::string scene;                 // path of the scene file (.dae or .zae)
  std::vector<Override> overrides;   // applied in this order
  std::vector<Command> schedule;     // sorted by time (stable: equal times keep their order)
  std::vector<std::string> record;   // ids sampled
  uint32_t every_n_steps = 1;        // one sample every N steps
  double duration_s = 0;             // simulated time [s]
};

/// One recorded id: rows x cols values per sample in `unit` ("" for none).
struct Channel {
  std::string id;
  std::string unit;
  uint32_t rows = 1;
  uint32_t cols = 1;
};

/// What one run recorded: times.size() samples of values_per_sample values each (row-major).
struct Recording {
  std::vector<Channel> channels;
  std::vector<double> times;  // [s]
  size_t values_per_sample = 0;
  std::vector<double> data;
};

/// The most runs an experiment file may expand to (its experiments times their sweeps).
constexpr size_t kMaxRuns = 10000;

/// Reads an experiment file (format above); scene and CSV paths come out absolute. Throws
/// FormatError naming the file, the experiment and what is wrong (also for more than kMaxRuns).
std::vector<Experiment> LoadFile(const std::string& path);

/// A command schedule from CSV: a header line, then `time [s],actuator,value` per line.
std::vector<Command> LoadScheduleCsv(const std::string& path);

/// Checks one experiment on its own (name, duration, sampling, schedule); throws FormatError.
void Validate(const Experiment& experiment);

/// Number of steps a run of `duration_s` takes at `time_step_s` (rounded to the nearest step).
uint64_t StepCount(double duration_s, double time_step_s);

}  // namespace caliper::experiment
