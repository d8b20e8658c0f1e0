#include "caliper/calibration/evaluator.h"

#include <cmath>
#include <thread>

#include "caliper/client/scene_transfer.h"
#include "caliper/logging/log.h"

namespace caliper::calibration {

Evaluator::Evaluator(const Spec& spec, client::ModelPool& pool) : spec_(spec), pool_(pool) {
  for (const auto& e : spec.experiments)
    if (!scenes_.count(e.scene)) scenes_[e.scene] = client::ReadScene(e.scene);
}

std::vector<double> Evaluator::ValuesOf(const std::vector<double>& unit) const {
  std::vector<double> values;
  for (size_t i = 0; i < spec_.parameters.size(); ++i)
    values.push_back(spec_.parameters[i].FromUnit(unit[i]));
  return values;
}

Evaluation Evaluator::Evaluate(const std::vector<double>& values, bool keep_recordings) {
  Evaluation out;
  ++evaluations_;
  for (size_t i = 0; i < spec_.experiments.size(); ++i) {
    const auto e = WithParameters(spec_.experiments[i], spec_.parameters, values);
    try {
      experiment::Recording r = pool_.Run(e, scenes_.at(e.scene));
      const auto channels = CompareRecording(r, spec_.measured[i], spec_.channels);
      out.channels.insert(out.channels.end(), channels.begin(), channels.end());
      if (keep_recordings) out.recordings.push_back(std::move(r));
    } catch (const client::RunFailedError& fault) {
      ++faults_;
      out.faulted = true;
      out.fault = fault.what();
      out.cost = kFaultCost;
      logging::Get("calibrate").warn("candidate faulted, cost %g: %s", kFaultCost, fault.what());
      return out;
    }
  }
  out.cost = Cost(out.channels);
  if (!std::isfinite(out.cost)) {
    // a simulation that ran but gave NaN or infinity is as bad as one that faulted
    ++faults_;
    out.faulted = true;
    out.fault = "the simulated channels are not finite";
    out.cost = kFaultCost;
  }
  return out;
}

double Evaluator::CostOfUnit(const std::vector<double>& unit) {
  return Evaluate(ValuesOf(unit)).cost;
}

}  // namespace caliper::calibration
