// Fuzz target: calibration files (caliper-calibrate's spec, JSON through Boost.PropertyTree)
// read by calibration::LoadSpec with the files they name: the experiment file and the measured
// CSVs (calibration::LoadMeasured).
// Input: the calibration file, then optionally a line `@@` and the experiment file, then a line
// `@@` and a measured CSV. The calibration file names them "FUZZ-runs.json" and
// "FUZZ-measured.csv" (`FUZZ-` is replaced by this process's file prefix, as in every file).
// Properties: LoadSpec and LoadMeasured either succeed or throw SpecError naming the file; an
// accepted spec has a measured table per experiment with increasing finite times and finite
// values, parameters with finite bounds lower < upper (log: lower > 0) whose unit mapping stays
// within them, finite non-negative channel weights and the optimiser's settings within bounds.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "caliper/calibration/calibration.h"
#include "fuzz_input.h"

namespace {

using caliper::fuzz::Check;
namespace cal = caliper::calibration;

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

void CheckMeasured(const cal::Measured& m, const std::string& what) {
  Check(m.times.size() >= 2, what + ": fewer than two rows accepted");
  Check(m.values.size() == m.columns.size() && m.units.size() == m.columns.size(),
        what + ": columns, units and values differ in number");
  for (size_t i = 0; i < m.times.size(); ++i) {
    Check(std::isfinite(m.times[i]), what + ": a time that is not finite");
    if (i > 0) Check(m.times[i - 1] < m.times[i], what + ": times that do not increase");
  }
  for (size_t c = 0; c < m.values.size(); ++c) {
    Check(m.values[c].size() == m.times.size(), what + ": a column shorter than the times");
    for (double v : m.values[c]) Check(std::isfinite(v), what + ": a value that is not finite");
    const double mid = 0.5 * (m.times.front() + m.times.back());
    Check(std::isfinite(m.At(c, mid)), what + ": an interpolated value that is not finite");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = caliper::fuzz::Parts(data, size, 3);
  const std::string runs_text = parts.size() > 1 ? parts[1] : "";
  const std::string csv_text = parts.size() > 2 ? parts[2] : "";
  const caliper::fuzz::InputFile csv(reinterpret_cast<const uint8_t*>(csv_text.data()),
                                     csv_text.size(), "measured.csv");
  std::string prefix = csv.path().substr(0, csv.path().size() - 12);  // .../caliper-fuzz-PID-
  prefix = prefix.substr(prefix.rfind('/') + 1);
  const std::string runs_json = Replace(runs_text, "FUZZ-", prefix);
  const caliper::fuzz::InputFile runs(reinterpret_cast<const uint8_t*>(runs_json.data()),
                                      runs_json.size(), "runs.json");
  const std::string spec_json = Replace(parts[0], "FUZZ-", prefix);
  const caliper::fuzz::InputFile file(reinterpret_cast<const uint8_t*>(spec_json.data()),
                                      spec_json.size(), "spec.json");
  const std::string& path = file.path();

  // the measured table on its own
  try {
    CheckMeasured(cal::LoadMeasured(csv.path()), "measured");
  } catch (const cal::SpecError& e) {
    const std::string message = e.what();
    Check(message.rfind(csv.path() + ":", 0) == 0,
          "a measured-file error that does not start with the file: " + message.substr(0, 300));
  } catch (const std::exception& e) {
    Check(false, std::string("LoadMeasured threw something else than SpecError: ") + e.what());
  }

  cal::Spec spec;
  try {
    spec = cal::LoadSpec(path);
  } catch (const cal::SpecError& e) {
    const std::string message = e.what();
    Check(message.rfind(path + ":", 0) == 0,
          "a SpecError that does not start with the file: " + message.substr(0, 300));
    return 0;
  } catch (const std::exception& e) {
    Check(false, std::string("LoadSpec threw something else than SpecError: ") + e.what());
  }
  Check(!spec.experiments.empty(), "a spec without experiments accepted");
  Check(spec.measured.size() == spec.experiments.size(), "not one measured table per experiment");
  for (const auto& m : spec.measured) CheckMeasured(m, m.file);
  Check(!spec.parameters.empty(), "a spec without parameters accepted");
  for (const cal::Parameter& p : spec.parameters) {
    const std::string what = "parameter " + p.id;
    Check(std::isfinite(p.lower) && std::isfinite(p.upper) && p.lower < p.upper,
          what + ": bounds not finite or not lower < upper");
    Check(!p.log_scale || p.lower > 0, what + ": a log scale with lower <= 0");
    for (double u : {0.0, 0.25, 0.5, 1.0}) {
      const double v = p.FromUnit(u);
      // within the bounds up to rounding
      const double slack = 1e-9 * (std::fabs(p.lower) + std::fabs(p.upper));
      Check(std::isfinite(v) && v >= p.lower - slack && v <= p.upper + slack,
            what + ": FromUnit(" + std::to_string(u) + ") out of the bounds");
      const double back = p.ToUnit(v);
      Check(std::isfinite(back) && back >= 0 && back <= 1, what + ": ToUnit out of [0, 1]");
    }
  }
  for (const auto& [id, w] : spec.channels) {
    Check(std::isfinite(w.weight) && w.weight >= 0, "channel " + id + ": weight");
    Check(w.from_s < w.to_s, "channel " + id + ": window not from < to");
  }
  const cal::Optimiser& o = spec.optimiser;
  Check(o.algorithm == "cmaes" || o.algorithm == "xnes", "optimiser: algorithm " + o.algorithm);
  Check(o.generations >= 1 && o.generations <= 1000000, "optimiser: generations out of bounds");
  Check(o.population >= 5 && o.population <= 10000, "optimiser: population out of bounds");
  Check(o.sigma0 > 0 && o.sigma0 <= 1, "optimiser: sigma0 out of (0, 1]");
  return 0;
}
