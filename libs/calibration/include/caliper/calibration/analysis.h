#pragma once
// What a calibration knows about itself, without CORBA or an optimiser: when the global search
// is done (and why), the measurements' noise floor, and at the optimum how sure the fit is (the
// parameters' covariance from the residuals' Jacobian, 95 % intervals, correlations, the noise
// per channel, and warnings that name what these experiments cannot determine).

#include <Eigen/Dense>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "caliper/calibration/calibration.h"

namespace caliper::calibration {

/// Whether the global search should stop after a generation, and why.
struct StopCheck {
  bool stop = false;
  bool converged = false;  ///< a criterion met (not just the budget spent)
  bool stalled = false;  ///< no progress over the window or the step collapsed (a restart may help)
  std::string reason;    ///< "converged: ..." / "stopped: ..." / "" to go on
  double improvement_per_generation = 0;  ///< relative, over the last window (0.03 = 3 %)
};

/// `history` holds the best cost after each generation since the search (re)started, its start
/// first; `spread` the populations' mean standard deviation in the unit box; `generations` those
/// done in all, against the `budget` (default: the history's).
StopCheck CheckStop(const std::vector<double>& history, double spread, unsigned budget,
                    const Optimiser& rule, unsigned generations = ~0u);

/// The relative improvement per generation over the recent generations of `history`: the last
/// `window`, at most a third of them (at least 3) (geometric mean; 0.03 = the cost fell 3 % per
/// generation).
double ImprovementPerGeneration(const std::vector<double>& history, unsigned window);

/// The cost a perfect model would have against these measurements, from the noise of each
/// measured column estimated by its second differences (white noise on a smooth signal).
double NoiseFloorCost(const Spec& spec);

/// One compared channel's block in a residual vector: `samples` residuals from `begin` on.
struct ResidualBlock {
  size_t experiment = 0;  ///< index in Spec::experiments
  std::string column, unit;
  double weight = 1, range = 1;
  size_t begin = 0, samples = 0;
};

/// The weights that make the sum of squared residuals the cost squared: weight / (sum of
/// weights * range^2 * samples) per block.
std::vector<double> BlockScales(const std::vector<ResidualBlock>& blocks);

struct ChannelNoise {
  std::string experiment, column, unit;
  double sigma = 0;  ///< estimated measurement noise [unit]
  size_t samples = 0;
};

struct ParameterUncertainty {
  double value = 0, sigma = 0;      ///< [parameter unit]
  double lower95 = 0, upper95 = 0;  ///< value -+ 1.96 sigma; +-inf when not determined
  bool determined = true;
  std::string most_sensitive_channel;  ///< "experiment: column" that moves most with it
};

struct Uncertainty {
  std::vector<ParameterUncertainty> parameters;
  Eigen::MatrixXd covariance;   ///< [unit_i * unit_j]; rows of undetermined ones are NaN
  Eigen::MatrixXd correlation;  ///< NaN where undetermined
  std::vector<ChannelNoise> noise;
  std::vector<std::string> warnings;
  size_t residuals = 0;
};

/// The uncertainty of a weighted least-squares fit at its optimum. `jacobian` is d(residual)/
/// d(unit) (residuals raw: simulated - measured, in each channel's unit; unit: the search space
/// [0, 1]^n); `residuals` the raw residuals; `blocks` their channels; `values` the fitted
/// values. The covariance is the estimator's (sandwich form: weights are the cost's, the noise
/// of each channel is estimated from its residuals), mapped to the parameters' units.
Uncertainty Analyse(const Spec& spec, const Eigen::MatrixXd& jacobian,
                    const std::vector<double>& residuals, const std::vector<ResidualBlock>& blocks,
                    const std::vector<double>& values, const UncertaintyOptions& options);

}  // namespace caliper::calibration
