// Fuzz target: experiment (batch) files, JSON through Boost.PropertyTree, read by
// experiment::LoadFile, and the command schedules in CSV it reads for "commands_csv"
// (experiment::LoadScheduleCsv).
// Input: the experiment file, then optionally a line `@@` and the schedule CSV. The JSON names
// the CSV as "FUZZ-schedule.csv": `FUZZ-` is replaced by this process's file prefix (the files
// are written side by side, caliper-fuzz-PID-NAME).
// Properties: LoadFile and LoadScheduleCsv either succeed or throw FormatError naming the file;
// every experiment accepted passes Validate, has a unique name, an absolute scene path, a
// schedule sorted by time with finite values, finite overrides and a countable number of steps.
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "caliper/experiment/experiment.h"
#include "fuzz_input.h"

namespace {

using caliper::fuzz::Check;
namespace ex = caliper::experiment;

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

void CheckSchedule(const std::vector<ex::Command>& schedule, bool sorted, const std::string& what) {
  for (size_t i = 0; i < schedule.size(); ++i) {
    Check(std::isfinite(schedule[i].time_s) && std::isfinite(schedule[i].value),
          what + ": a command with a time or value that is not finite");
    if (sorted && i > 0)
      Check(schedule[i - 1].time_s <= schedule[i].time_s, what + ": the schedule is not sorted");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = caliper::fuzz::Parts(data, size, 2);
  const std::string csv_text = parts.size() > 1 ? parts[1] : "time [s],actuator,value\n";
  const caliper::fuzz::InputFile csv(reinterpret_cast<const uint8_t*>(csv_text.data()),
                                     csv_text.size(), "schedule.csv");
  const std::string prefix = csv.path().substr(0, csv.path().size() - 12);  // ...-PID-
  const std::string json = Replace(parts[0], "FUZZ-", prefix.substr(prefix.rfind('/') + 1));
  const caliper::fuzz::InputFile file(reinterpret_cast<const uint8_t*>(json.data()), json.size(),
                                      "experiment.json");
  const std::string& path = file.path();

  // the schedule on its own
  try {
    CheckSchedule(ex::LoadScheduleCsv(csv.path()), false, "schedule");
  } catch (const ex::FormatError& e) {
    const std::string message = e.what();
    Check(message.rfind(csv.path() + ": ", 0) == 0,
          "a schedule error that does not start with the file: " + message.substr(0, 300));
  } catch (const std::exception& e) {
    Check(false, std::string("LoadScheduleCsv threw something else than FormatError: ") + e.what());
  }

  std::vector<ex::Experiment> experiments;
  try {
    experiments = ex::LoadFile(path);
  } catch (const ex::FormatError& e) {
    const std::string message = e.what();
    Check(message.rfind(path + ":", 0) == 0,
          "a FormatError that does not start with the file: " + message.substr(0, 300));
    return 0;
  } catch (const std::exception& e) {
    Check(false, std::string("LoadFile threw something else than FormatError: ") + e.what());
  }
  Check(!experiments.empty(), "LoadFile accepted a file without experiments");
  std::set<std::string> names;
  for (const ex::Experiment& e : experiments) {
    try {
      ex::Validate(e);
    } catch (const std::exception& error) {
      Check(false, std::string("an accepted experiment fails Validate: ") + error.what());
    }
    Check(names.insert(e.name).second, "two experiments named '" + e.name + "'");
    Check(!e.scene.empty() && e.scene[0] == '/', "a scene path that is not absolute: " + e.scene);
    Check(e.duration_s > 0 && e.duration_s <= 1e6, e.name + ": duration_s out of (0, 1e6]");
    Check(e.every_n_steps >= 1, e.name + ": every_n_steps < 1");
    CheckSchedule(e.schedule, true, e.name);
    for (const auto& c : e.schedule)
      Check(c.time_s >= 0 && !c.actuator.empty(), e.name + ": a command before 0 s or unnamed");
    for (const auto& o : e.overrides) {
      Check(!o.id.empty(), e.name + ": an override without an id");
      for (double v : o.values)
        Check(std::isfinite(v), e.name + ": override " + o.id + " not finite");
    }
    try {
      Check(ex::StepCount(e.duration_s, 1e-3) >= 1 || e.duration_s < 5e-4,
            e.name + ": no step in a run of positive duration");
    } catch (const std::exception& error) {
      Check(false, e.name + ": StepCount refused an accepted duration: " + error.what());
    }
  }
  return 0;
}
