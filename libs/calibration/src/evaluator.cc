#include "caliper/calibration/evaluator.h"

#include <cmath>
#include <future>
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
  EvaluateOptions options;
  options.keep_recordings = keep_recordings;
  return Evaluate(values, options);
}

Evaluation Evaluator::Evaluate(const std::vector<double>& values, const EvaluateOptions& options) {
  Evaluation out;
  ++evaluations_;
  const Timing timing = TimingOf(spec_.parameters, values);
  for (size_t i = 0; i < spec_.experiments.size(); ++i) {
    const bool held_out = spec_.held_out[i];
    if (held_out && !options.held_out) continue;
    const auto e = WithParameters(spec_.experiments[i], spec_.parameters, values);
    try {
      experiment::Recording r = pool_.Run(e, scenes_.at(e.scene));
      std::vector<double> residuals;
      auto channels = CompareRecording(r, spec_.measured[i], spec_.channels, timing,
                                       options.residuals && !held_out ? &residuals : nullptr);
      for (auto& c : channels) c.experiment = i;
      if (options.residuals && !held_out) {
        size_t begin = out.residuals.size();
        for (const auto& c : channels) {
          out.blocks.push_back({i, c.column, c.unit, c.weight, c.range, begin, c.samples});
          begin += c.samples;
        }
        out.residuals.insert(out.residuals.end(), residuals.begin(), residuals.end());
      }
      auto& into = held_out ? out.held_out_channels : out.channels;
      into.insert(into.end(), channels.begin(), channels.end());
      if (options.keep_recordings) {
        out.recordings.push_back(std::move(r));
        out.recorded.push_back(i);
      }
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
  if (options.held_out && !out.held_out_channels.empty())
    out.held_out_cost = Cost(out.held_out_channels);
  bool finite =
      std::isfinite(out.cost) && (out.held_out_cost == -1 || std::isfinite(out.held_out_cost));
  for (double r : out.residuals) finite = finite && std::isfinite(r);
  if (!finite) {
    // a simulation that ran but gave NaN or infinity is as bad as one that faulted
    ++faults_;
    out.faulted = true;
    out.fault = "the simulated channels are not finite";
    out.cost = kFaultCost;
  }
  return out;
}

std::vector<Evaluation> Evaluator::EvaluateMany(const std::vector<std::vector<double>>& values,
                                                const EvaluateOptions& options) {
  // at most one candidate per Model at a time: more threads would only queue in the pool
  const size_t workers = std::max<size_t>(1, std::min(values.size(), pool_.size()));
  std::vector<Evaluation> out(values.size());
  std::atomic<size_t> next{0};
  std::vector<std::future<void>> running;
  for (size_t w = 0; w < workers; ++w)
    running.push_back(std::async(std::launch::async, [&] {
      for (size_t k; (k = next++) < values.size();) out[k] = Evaluate(values[k], options);
    }));
  for (auto& r : running) r.get();  // rethrows a set-up error
  return out;
}

std::vector<std::optional<std::vector<double>>> Evaluator::Residuals(
    const std::vector<std::vector<double>>& units, bool weighted) {
  std::vector<std::vector<double>> values;
  for (const auto& u : units) values.push_back(ValuesOf(u));
  EvaluateOptions options;
  options.residuals = true;
  const auto evaluations = EvaluateMany(values, options);
  std::vector<std::optional<std::vector<double>>> out;
  for (const auto& e : evaluations) {
    if (e.faulted) {
      out.emplace_back();
      continue;
    }
    if (!weighted) {
      out.emplace_back(e.residuals);
      continue;
    }
    const std::vector<double> scales = BlockScales(e.blocks);
    std::vector<double> r = e.residuals;
    for (size_t b = 0; b < e.blocks.size(); ++b)
      for (size_t i = 0; i < e.blocks[b].samples; ++i)
        r[e.blocks[b].begin + i] *= std::sqrt(scales[b]);
    out.emplace_back(std::move(r));
  }
  return out;
}

double Evaluator::CostOfUnit(const std::vector<double>& unit) {
  return Evaluate(ValuesOf(unit)).cost;
}

}  // namespace caliper::calibration
