#include "caliper/calibration/analysis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace caliper::calibration {

namespace {

std::string Format(double v, int digits = 3) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

std::string Percent(double fraction) {
  return Format(100 * fraction, fraction < 0.01 ? 2 : 3) + " %";
}

}  // namespace

double ImprovementPerGeneration(const std::vector<double>& history, unsigned window) {
  if (history.size() < 2) return 0;
  // recent progress: the last third of the run at most (an early drop is not "still improving")
  const size_t generations = history.size() - 1;
  const size_t k = std::min<size_t>({window, std::max<size_t>(3, generations / 3), generations});
  const double before = history[history.size() - 1 - k], now = history.back();
  if (!(before > 0) || !(now > 0)) return before > now ? 1 : 0;
  return 1 - std::pow(now / before, 1.0 / static_cast<double>(k));
}

StopCheck CheckStop(const std::vector<double>& history, double spread, unsigned budget,
                    const Optimiser& rule, unsigned generations) {
  StopCheck out;
  const unsigned generation = history.empty() ? 0 : static_cast<unsigned>(history.size() - 1);
  const double best = history.empty() ? HUGE_VAL : history.back();
  out.improvement_per_generation = ImprovementPerGeneration(history, rule.window);
  if (rule.target_cost > 0 && best <= rule.target_cost) {
    out.stop = out.converged = true;
    out.reason =
        "converged: cost " + Format(best, 4) + " reached the target " + Format(rule.target_cost, 4);
    return out;
  }
  if (generation >= rule.window) {
    const double before = history[generation - rule.window];
    const double change = before > 0 ? (before - best) / before : 0;
    if (change <= rule.cost_tolerance) {
      out.stop = out.converged = out.stalled = true;
      out.reason = "converged: cost changed less than " + Format(rule.cost_tolerance) + " over " +
                   std::to_string(rule.window) + " generations";
      return out;
    }
  }
  if (generation > 0 && spread < rule.step_tolerance) {
    out.stop = out.converged = out.stalled = true;
    out.reason = "converged: the search's step fell to " + Format(spread) +
                 " of the search box (step_tolerance " + Format(rule.step_tolerance) + ")";
    return out;
  }
  if ((generations == ~0u ? generation : generations) >= budget) {
    out.stop = true;
    out.reason =
        "stopped: budget of " + std::to_string(budget) + " generations spent, " +
        (out.improvement_per_generation > 1e-4
             ? "still improving " + Percent(out.improvement_per_generation) + " per generation"
             : "improving less than 0.01 % per generation");
  }
  return out;
}

double NoiseFloorCost(const Spec& spec) {
  double sum = 0, weights = 0;
  for (size_t e = 0; e < spec.measured.size(); ++e) {
    if (spec.held_out[e]) continue;
    const Measured& m = spec.measured[e];
    for (size_t c = 0; c < m.columns.size(); ++c) {
      const auto& v = m.values[c];
      if (v.size() < 5) continue;
      double w = 1;
      if (const auto it = spec.channels.find(m.columns[c]); it != spec.channels.end())
        w = it->second.weight;
      // white noise of variance s^2 gives second differences of variance 6 s^2
      double square = 0;
      for (size_t i = 1; i + 1 < v.size(); ++i) {
        const double d = v[i + 1] - 2 * v[i] + v[i - 1];
        square += d * d;
      }
      const double sigma = std::sqrt(square / static_cast<double>(v.size() - 2) / 6);
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      const double range = std::max(*hi - *lo, 1e-12);
      sum += w * (sigma / range) * (sigma / range);
      weights += w;
    }
  }
  return weights > 0 ? std::sqrt(sum / weights) : 0;
}

std::vector<double> BlockScales(const std::vector<ResidualBlock>& blocks) {
  double weights = 0;
  for (const auto& b : blocks)
    if (b.samples) weights += b.weight;
  std::vector<double> out;
  for (const auto& b : blocks)
    out.push_back(b.samples && weights > 0
                      ? b.weight / (weights * b.range * b.range * static_cast<double>(b.samples))
                      : 0);
  return out;
}

namespace {

// The noise variance of each channel, from its residuals (degrees of freedom shared out by
// samples), also into out.noise as standard deviations.
std::vector<double> NoiseVariances(const Spec& spec, const std::vector<double>& residuals,
                                   const std::vector<ResidualBlock>& blocks, Eigen::Index n,
                                   Eigen::Index m, Uncertainty& out) {
  const double dof = m > n ? 1.0 - static_cast<double>(n) / static_cast<double>(m) : 1.0;
  std::vector<double> variance(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    double square = 0;
    for (size_t i = 0; i < blocks[b].samples; ++i)
      square += residuals[blocks[b].begin + i] * residuals[blocks[b].begin + i];
    const double samples = static_cast<double>(std::max<size_t>(blocks[b].samples, 1));
    variance[b] = square / (samples * dof);
    out.noise.push_back({spec.experiments[blocks[b].experiment].name, blocks[b].column,
                         blocks[b].unit, std::sqrt(variance[b]), blocks[b].samples});
  }
  return variance;
}

// The warnings of Analyse, each with what would help.
void AddWarnings(const Spec& spec, const Eigen::MatrixXd& jacobian,
                 const std::vector<ResidualBlock>& blocks, const std::vector<bool>& moves,
                 const std::vector<bool>& determined, const UncertaintyOptions& options,
                 Uncertainty& out) {
  const Eigen::Index n = jacobian.cols();
  const auto name = [&](const ResidualBlock& b) {
    return spec.experiments[b.experiment].name + ": " + b.column;
  };
  const auto id = [&](Eigen::Index j) { return spec.parameters[static_cast<size_t>(j)].id; };
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto& pu = out.parameters[static_cast<size_t>(j)];
    if (!moves[static_cast<size_t>(j)]) {
      out.warnings.push_back(id(j) +
                             ": no channel of the fitted experiments changes with it, so they "
                             "cannot determine it; record a channel it drives, or add an "
                             "experiment that excites it");
    } else if (!pu.determined) {
      std::string with;
      for (Eigen::Index i = 0; i < n; ++i)
        if (i != j && moves[static_cast<size_t>(i)] && !determined[static_cast<size_t>(i)])
          with += (with.empty() ? "" : ", ") + id(i);
      out.warnings.push_back(
          id(j) + ": only a combination of it" + (with.empty() ? "" : " with " + with) +
          " is determined by these experiments (their effects on every channel are "
          "proportional); fix one of them, or add an experiment where they act differently");
    } else if (const Parameter& q = spec.parameters[static_cast<size_t>(j)];
               // a timing parameter's value may be near 0: its search range is the scale
               1.96 * pu.sigma >
               options.max_relative_interval *
                   (q.kind == ParameterKind::kScene ? std::abs(pu.value) : q.upper - q.lower)) {
      const bool timing = q.kind != ParameterKind::kScene;
      const double scale = timing ? q.upper - q.lower : std::abs(pu.value);
      out.warnings.push_back(
          id(j) + ": its 95 % interval is +-" + Format(1.96 * pu.sigma) + " (" +
          Percent(1.96 * pu.sigma / scale) + (timing ? " of its search range" : " of the value") +
          ", more than " + Percent(options.max_relative_interval) +
          "); the channel that moves most with it is " + pu.most_sensitive_channel +
          ": longer or stronger excitation there, or a higher weight, would "
          "pin it");
    }
  }
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j) {
      const double rho = out.correlation(i, j);
      if (!(std::abs(rho) > options.max_correlation)) continue;
      // the channel where the two act least alike separates them best
      std::string separates;
      double least = 2;
      for (size_t b = 0; b < blocks.size(); ++b) {
        const auto rows = static_cast<Eigen::Index>(blocks[b].samples);
        const auto begin = static_cast<Eigen::Index>(blocks[b].begin);
        const Eigen::VectorXd ci = jacobian.block(begin, i, rows, 1);
        const Eigen::VectorXd cj = jacobian.block(begin, j, rows, 1);
        if (ci.norm() < 1e-300 || cj.norm() < 1e-300) continue;
        const double alike = std::abs(ci.dot(cj)) / (ci.norm() * cj.norm());
        if (alike < least) {
          least = alike;
          separates = name(blocks[b]);
        }
      }
      out.warnings.push_back(id(i) + " and " + id(j) + " are correlated (" + Format(rho) +
                             "): these experiments determine mainly a combination of the two" +
                             (separates.empty() ? std::string()
                                                : "; " + separates +
                                                      " tells them apart best: weight it more, "
                                                      "or add an experiment that excites it"));
    }
}

}  // namespace

Uncertainty Analyse(const Spec& spec, const Eigen::MatrixXd& jacobian,
                    const std::vector<double>& residuals, const std::vector<ResidualBlock>& blocks,
                    const std::vector<double>& values, const UncertaintyOptions& options) {
  const Eigen::Index n = jacobian.cols();
  const Eigen::Index m = jacobian.rows();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Uncertainty out;
  out.residuals = static_cast<size_t>(m);
  const auto name = [&](const ResidualBlock& b) {
    return spec.experiments[b.experiment].name + ": " + b.column;
  };

  const std::vector<double> variance = NoiseVariances(spec, residuals, blocks, n, m, out);

  // per row: the cost's weight a and the noise variance s^2
  const std::vector<double> scales = BlockScales(blocks);
  Eigen::VectorXd a = Eigen::VectorXd::Zero(m), s2 = Eigen::VectorXd::Zero(m);
  for (size_t b = 0; b < blocks.size(); ++b)
    for (size_t i = 0; i < blocks[b].samples; ++i) {
      a(static_cast<Eigen::Index>(blocks[b].begin + i)) = scales[b];
      s2(static_cast<Eigen::Index>(blocks[b].begin + i)) = variance[b];
    }

  // d(value)/d(unit): the search space's scaling
  Eigen::VectorXd dvalue(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Parameter& p = spec.parameters[static_cast<size_t>(j)];
    dvalue(j) = p.log_scale ? values[static_cast<size_t>(j)] * std::log(p.upper / p.lower)
                            : p.upper - p.lower;
  }

  // which parameters move any channel: a column of the weighted Jacobian next to nothing
  const Eigen::MatrixXd weighted = a.cwiseSqrt().asDiagonal() * jacobian;
  Eigen::VectorXd column_norm = weighted.colwise().norm();
  const double largest = column_norm.size() ? column_norm.maxCoeff() : 0;
  std::vector<bool> moves(static_cast<size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j)
    moves[static_cast<size_t>(j)] =
        column_norm(j) > 1e-9 * std::max(largest, 1e-300) && column_norm(j) > 1e-12;

  out.parameters.resize(static_cast<size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j) {
    auto& pu = out.parameters[static_cast<size_t>(j)];
    pu.value = values[static_cast<size_t>(j)];
    // the channel that moves most with it
    double best = -1;
    for (size_t b = 0; b < blocks.size(); ++b) {
      const double move =
          std::sqrt(scales[b]) * jacobian
                                     .block(static_cast<Eigen::Index>(blocks[b].begin), j,
                                            static_cast<Eigen::Index>(blocks[b].samples), 1)
                                     .norm();
      if (move > best) {
        best = move;
        pu.most_sensitive_channel = name(blocks[b]);
      }
    }
  }

  // the covariance of the weighted estimator over the parameters that move something:
  // H = J' A J, B = J' A S A J, cov = H^-1 B H^-1 (S: the channels' noise variances)
  std::vector<Eigen::Index> kept;
  for (Eigen::Index j = 0; j < n; ++j)
    if (moves[static_cast<size_t>(j)]) kept.push_back(j);
  const Eigen::Index k = static_cast<Eigen::Index>(kept.size());
  Eigen::MatrixXd jk(m, k);
  for (Eigen::Index c = 0; c < k; ++c) jk.col(c) = jacobian.col(kept[static_cast<size_t>(c)]);
  const Eigen::MatrixXd aj = a.asDiagonal() * jk;
  const Eigen::MatrixXd h = jk.transpose() * aj;
  const Eigen::MatrixXd meat = aj.transpose() * s2.asDiagonal() * aj;
  // H scaled to a unit diagonal, then inverted through its eigenvalues: a direction with a
  // vanishing one is a combination that the experiments do not determine. None kept (no
  // parameter moves anything): nothing to invert (Eigen's solver crashes on an empty matrix).
  std::vector<bool> determined_k(static_cast<size_t>(k), true);
  Eigen::MatrixXd cov_unit_k(k, k);
  if (k > 0) {
    Eigen::VectorXd d = h.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd hs = d.asDiagonal() * h * d.asDiagonal();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(hs);
    const Eigen::VectorXd lambda = eigen.eigenvalues();
    const double cutoff = 1e-12 * std::max(lambda.maxCoeff(), 1e-300);
    Eigen::VectorXd inverse_lambda(k);
    for (Eigen::Index i = 0; i < k; ++i) {
      if (lambda(i) > cutoff) {
        inverse_lambda(i) = 1 / lambda(i);
        continue;
      }
      inverse_lambda(i) = 0;
      for (Eigen::Index c = 0; c < k; ++c)
        if (std::abs(eigen.eigenvectors()(c, i)) > 0.1)
          determined_k[static_cast<size_t>(c)] = false;
    }
    const Eigen::MatrixXd hs_inverse =
        eigen.eigenvectors() * inverse_lambda.asDiagonal() * eigen.eigenvectors().transpose();
    const Eigen::MatrixXd h_inverse = d.asDiagonal() * hs_inverse * d.asDiagonal();
    const Eigen::MatrixXd sandwich = h_inverse * meat * h_inverse;
    cov_unit_k = (sandwich + sandwich.transpose()) / 2;  // symmetric exactly
  }

  out.covariance = Eigen::MatrixXd::Constant(n, n, nan);
  out.correlation = Eigen::MatrixXd::Constant(n, n, nan);
  std::vector<bool> determined(static_cast<size_t>(n), false);
  for (Eigen::Index r = 0; r < k; ++r)
    determined[static_cast<size_t>(kept[static_cast<size_t>(r)])] =
        determined_k[static_cast<size_t>(r)];
  for (Eigen::Index r = 0; r < k; ++r)
    for (Eigen::Index c = 0; c < k; ++c) {
      const Eigen::Index i = kept[static_cast<size_t>(r)], j = kept[static_cast<size_t>(c)];
      if (!determined[static_cast<size_t>(i)] || !determined[static_cast<size_t>(j)]) continue;
      // (a product that commutes exactly: the matrix stays symmetric); a parameter that acts only
      // in steps (a command delay: time steps) is known to a step at best: a uniform
      // quantisation's variance, resolution^2 / 12, on top
      const double resolution = i == j ? spec.parameters[static_cast<size_t>(i)].resolution : 0;
      out.covariance(i, j) =
          dvalue(i) * dvalue(j) * cov_unit_k(r, c) + resolution * resolution / 12;
    }
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j)
      if (determined[static_cast<size_t>(i)] && determined[static_cast<size_t>(j)])
        out.correlation(i, j) =
            i == j ? 1.0
                   : out.covariance(i, j) / std::sqrt(out.covariance(i, i) * out.covariance(j, j));

  for (Eigen::Index j = 0; j < n; ++j) {
    auto& pu = out.parameters[static_cast<size_t>(j)];
    pu.determined = determined[static_cast<size_t>(j)];
    if (!pu.determined) {
      pu.sigma = inf;
      pu.lower95 = -inf;
      pu.upper95 = inf;
      continue;
    }
    pu.sigma = std::sqrt(std::max(out.covariance(j, j), 0.0));
    pu.lower95 = pu.value - 1.96 * pu.sigma;
    pu.upper95 = pu.value + 1.96 * pu.sigma;
  }

  AddWarnings(spec, jacobian, blocks, moves, determined, options, out);
  return out;
}

}  // namespace caliper::calibration
