#pragma once
// The local refinement after the global search: Levenberg-Marquardt (Ceres Solver) on the
// weighted residual vector, in the unit search space with its bounds. Ceres because it is made
// for exactly this (bounds, a robust trust region, a termination reason in words, callbacks for
// progress and Ctrl-C); its numeric differentiation evaluates columns one after another, so the
// Jacobian here is ours: every finite-difference column is one candidate, and a whole Jacobian
// is one batch that the caller spreads over every free Model.

#include <Eigen/Dense>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "caliper/calibration/calibration.h"

namespace caliper::calibration {

/// Residuals of several points at once (the caller runs them in parallel); nullopt for a point
/// whose simulation faulted.
using Residuals = std::vector<double>;
using BatchResiduals =
    std::function<std::vector<std::optional<Residuals>>(const std::vector<std::vector<double>>&)>;

/// The finite-difference Jacobian at `unit` (whose residuals are `base`): one batch of n
/// (forward) or 2n (central) points. `steps` per parameter in the unit box; a step that would
/// leave [0, 1] is taken the other way (one-sided), and so is a central difference one side of
/// which faulted. Throws std::runtime_error when a column has no usable point.
Eigen::MatrixXd Jacobian(const BatchResiduals& batch, const std::vector<double>& unit,
                         const Residuals& base, const std::vector<double>& steps, bool central);

struct RefineProgress {
  unsigned iteration = 0;
  double cost = 0;  ///< the cost (square root of the sum of squared residuals)
  uint64_t evaluations = 0;
  std::vector<double> unit;
};

struct RefineResult {
  std::vector<double> unit;
  double start_cost = 0, cost = 0;
  unsigned iterations = 0;
  uint64_t evaluations = 0;  ///< points evaluated
  bool converged = false;
  bool interrupted = false;
  std::string reason;  ///< "converged: ..." / "stopped: ..."
};

struct RefineOptions {
  unsigned max_iterations = 30;
  bool central = true;
  std::vector<double> steps;                                ///< per parameter, in the unit box
  std::function<bool()> interrupted;                        ///< polled between iterations
  std::function<void(const RefineProgress&)> on_iteration;  ///< after each, with the point
};

/// Levenberg-Marquardt from `start` (unit box) on the residuals of `batch` (`residuals` of them).
RefineResult Refine(const BatchResiduals& batch, const std::vector<double>& start, size_t residuals,
                    const RefineOptions& options);

}  // namespace caliper::calibration
