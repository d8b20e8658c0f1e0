// The calibration's analysis without a simulator: the global search's stopping rules, the noise
// floor of measurements, the finite-difference Jacobian and Levenberg-Marquardt refinement on a
// synthetic decay y(t) = A exp(-t / tau), and the uncertainty at the optimum checked against
// closed forms (weighted mean, straight line) and against the truth over many noise draws.
#include "caliper/calibration/analysis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <random>

#include "caliper/calibration/refine.h"

namespace caliper::calibration {
namespace {

// A spec of one fitted experiment named `name` with these parameters (what Analyse reads).
Spec OneExperiment(const std::string& name, std::vector<Parameter> parameters = {}) {
  experiment::Experiment e;
  e.name = name;
  Spec spec;
  spec.experiments = {e};
  spec.held_out = {false};
  spec.parameters = std::move(parameters);
  return spec;
}

constexpr double kInf = std::numeric_limits<double>::infinity();
const double kPi = std::acos(-1.0);

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The warnings that mention every one of `parts`, joined (empty: none).
std::string WarningWith(const Uncertainty& u, const std::vector<std::string>& parts) {
  std::string out;
  for (const auto& w : u.warnings) {
    bool all = true;
    for (const auto& p : parts) all = all && Contains(w, p);
    if (all) out += w + "\n";
  }
  return out;
}

std::string AllWarnings(const Uncertainty& u) {
  std::string out;
  for (const auto& w : u.warnings) out += w + "\n";
  return out;
}

// ---------------------------------------------------------------------------------------------
// Stopping rules

Optimiser Rule() {
  Optimiser rule;
  rule.window = 20;
  rule.cost_tolerance = 1e-6;
  rule.step_tolerance = 1e-4;
  rule.target_cost = 0;
  return rule;
}

std::vector<double> Geometric(double c0, double factor, unsigned generations) {
  std::vector<double> h;
  for (unsigned g = 0; g <= generations; ++g) h.push_back(c0 * std::pow(factor, g));
  return h;
}

TEST(CheckStop, ATargetReachedConverges) {
  Optimiser rule = Rule();
  rule.target_cost = 0.01;
  const StopCheck reached = CheckStop({1, 0.5, 0.009}, 0.2, 60, rule);
  EXPECT_TRUE(reached.stop);
  EXPECT_TRUE(reached.converged);
  EXPECT_FALSE(reached.stalled);
  EXPECT_TRUE(Contains(reached.reason, "converged:")) << reached.reason;
  EXPECT_TRUE(Contains(reached.reason, "target 0.01")) << reached.reason;
  EXPECT_TRUE(Contains(reached.reason, "0.009")) << reached.reason;
  // just above it: go on
  const StopCheck above = CheckStop({1, 0.5, 0.011}, 0.2, 60, rule);
  EXPECT_FALSE(above.stop);
  EXPECT_EQ(above.reason, "");
  // no target (0): a cost of 0 is not a reason by itself
  EXPECT_FALSE(CheckStop({1, 0.5, 0.0}, 0.2, 60, Rule()).stop);
}

TEST(CheckStop, AFlatCostOverTheWindowConverges) {
  const std::vector<double> flat(21, 0.3);  // the start and 20 generations without change
  const StopCheck s = CheckStop(flat, 0.2, 60, Rule());
  EXPECT_TRUE(s.stop);
  EXPECT_TRUE(s.converged);
  EXPECT_TRUE(s.stalled);
  EXPECT_EQ(s.reason, "converged: cost changed less than 1e-06 over 20 generations");
  EXPECT_EQ(s.improvement_per_generation, 0);
  // one generation short of the window: too early to judge
  EXPECT_FALSE(CheckStop(std::vector<double>(20, 0.3), 0.2, 60, Rule()).stop);
  // a change of 1e-5 over the window (above the tolerance) goes on ...
  std::vector<double> slow = flat;
  slow.back() = 0.3 * (1 - 1e-5);
  EXPECT_FALSE(CheckStop(slow, 0.2, 60, Rule()).stop);
  // ... one of 1e-7 does not; only the last window counts, not the start
  slow.back() = 0.3 * (1 - 1e-7);
  slow.insert(slow.begin(), 5.0);
  EXPECT_TRUE(CheckStop(slow, 0.2, 60, Rule()).converged);
}

TEST(CheckStop, ASpreadBelowTheStepToleranceConverges) {
  const StopCheck s = CheckStop({1, 0.9}, 5e-5, 60, Rule());
  EXPECT_TRUE(s.stop);
  EXPECT_TRUE(s.converged);
  EXPECT_TRUE(s.stalled);
  EXPECT_TRUE(Contains(s.reason, "converged:")) << s.reason;
  EXPECT_TRUE(Contains(s.reason, "step_tolerance 0.0001")) << s.reason;
  EXPECT_TRUE(Contains(s.reason, "5e-05")) << s.reason;
  // not before the first generation, nor at a spread above the tolerance
  EXPECT_FALSE(CheckStop({1}, 5e-5, 60, Rule()).stop);
  EXPECT_FALSE(CheckStop({1, 0.9}, 2e-4, 60, Rule()).stop);
}

TEST(CheckStop, ABudgetSpentWhileImprovingIsNotConvergence) {
  // c_g = c0 * 0.97^g: 3 % per generation, far from flat over the window
  const std::vector<double> history = Geometric(2.0, 0.97, 60);
  const StopCheck s = CheckStop(history, 0.1, 60, Rule());
  EXPECT_TRUE(s.stop);
  EXPECT_FALSE(s.converged);
  EXPECT_FALSE(s.stalled);
  EXPECT_NEAR(s.improvement_per_generation, 0.03, 1e-12);
  EXPECT_EQ(s.reason,
            "stopped: budget of 60 generations spent, still improving 3 % per generation");
  EXPECT_NEAR(ImprovementPerGeneration(history, 20), 0.03, 1e-12);
  // 0.5 % per generation: the percentage follows the history
  const StopCheck half = CheckStop(Geometric(2.0, 0.995, 60), 0.1, 60, Rule());
  EXPECT_NEAR(half.improvement_per_generation, 0.005, 1e-12);
  EXPECT_EQ(half.reason,
            "stopped: budget of 60 generations spent, still improving 0.5 % per generation");
  // below 0.01 % per generation (yet above the cost tolerance over the window)
  const StopCheck crawl = CheckStop(Geometric(2.0, 1 - 2e-5, 60), 0.1, 60, Rule());
  EXPECT_TRUE(crawl.stop);
  EXPECT_FALSE(crawl.converged);
  EXPECT_EQ(crawl.reason,
            "stopped: budget of 60 generations spent, improving less than 0.01 % per generation");
  // one generation before the budget: go on
  EXPECT_FALSE(CheckStop(Geometric(2.0, 0.97, 59), 0.1, 60, Rule()).stop);
}

TEST(CheckStop, NothingMetGoesOn) {
  const StopCheck s = CheckStop(Geometric(1.0, 0.9, 30), 0.05, 60, Rule());
  EXPECT_FALSE(s.stop);
  EXPECT_FALSE(s.converged);
  EXPECT_FALSE(s.stalled);
  EXPECT_EQ(s.reason, "");
  EXPECT_NEAR(s.improvement_per_generation, 0.1, 1e-12);
  EXPECT_FALSE(CheckStop({}, 0.05, 60, Rule()).stop);
}

TEST(ImprovementPerGeneration, IsTheGeometricMeanOverTheRecentGenerations) {
  // 10 % per generation for 5 generations, then 1 % for 4
  std::vector<double> h = Geometric(1.0, 0.9, 5);
  for (int g = 0; g < 4; ++g) h.push_back(h.back() * 0.99);
  EXPECT_NEAR(ImprovementPerGeneration(h, 4), 0.01, 1e-12);
  // a window longer than the run: its last third (at least 3), not the early drop
  EXPECT_NEAR(ImprovementPerGeneration(h, 100), 0.01, 1e-12);
  // 12 generations at 10 %, then 6 at 1 %: the last 6 (a third of 18)
  std::vector<double> g = Geometric(1.0, 0.9, 12);
  for (int k = 0; k < 6; ++k) g.push_back(g.back() * 0.99);
  EXPECT_NEAR(ImprovementPerGeneration(g, 100), 0.01, 1e-12);
  // 5 generations: at least 3 of them
  const std::vector<double> five = {1.0, 0.5, 0.5, 0.5 * 0.9, 0.5 * 0.81, 0.5 * 0.729};
  EXPECT_NEAR(ImprovementPerGeneration(five, 100), 0.1, 1e-12);
  EXPECT_EQ(ImprovementPerGeneration({1.0}, 20), 0);
  EXPECT_EQ(ImprovementPerGeneration({1.0, 2.0, 2.0}, 1), 0);
}

// ---------------------------------------------------------------------------------------------
// Noise floor

TEST(NoiseFloorCost, IsTheNoiseOverTheRange) {
  const double s = 0.02, range = 2;
  std::mt19937_64 random(3);
  std::normal_distribution<double> noise(0, 1);
  Spec spec = OneExperiment("e");
  Measured m;
  m.columns = {"y"};
  m.units = {"m"};
  m.values.resize(1);
  for (int i = 0; i < 1000; ++i) {
    const double t = i * 1e-3;
    m.times.push_back(t);
    m.values[0].push_back(std::sin(2 * kPi * t) + s * noise(random));
  }
  spec.measured = {m};
  const double floor = NoiseFloorCost(spec);
  std::printf("noise floor %.5f, s / r %.5f\n", floor, s / range);
  EXPECT_NEAR(floor, s / range, 0.15 * s / range);

  // a second column, weighted 3, five times noisier: the weighted mean of the squares, over
  // each column's measured range (as the cost's), which the noise widens here
  m.columns.push_back("z");
  m.units.push_back("m");
  m.values.emplace_back();
  for (double t : m.times) m.values[1].push_back(std::cos(2 * kPi * t) + 5 * s * noise(random));
  spec.measured = {m};
  spec.channels["z"].weight = 3;
  const double two = NoiseFloorCost(spec);
  const auto [lo, hi] = std::minmax_element(m.values[1].begin(), m.values[1].end());
  const double range_z = *hi - *lo;
  EXPECT_GT(range_z, 2.3);  // so that the measured range matters
  const double expected =
      std::sqrt((std::pow(s / range, 2) + 3 * std::pow(5 * s / range_z, 2)) / 4);
  EXPECT_NEAR(two, expected, 0.15 * expected);

  // a held-out experiment, however noisy, does not count
  Measured loud = m;
  for (auto& column : loud.values)
    for (auto& v : column) v += 0.5 * noise(random);
  experiment::Experiment louder;
  louder.name = "loud";
  spec.experiments.push_back(louder);
  spec.measured.push_back(loud);
  spec.held_out = {false, true};
  EXPECT_DOUBLE_EQ(NoiseFloorCost(spec), two);
  spec.held_out = {false, false};
  EXPECT_GT(NoiseFloorCost(spec), 2 * two);
}

TEST(NoiseFloorCost, IsZeroForASmoothSignal) {
  Spec spec = OneExperiment("e");
  Measured m;
  m.columns = {"y"};
  m.values.resize(1);
  for (int i = 0; i < 100; ++i) {
    m.times.push_back(i);
    m.values[0].push_back(3 * i + 1);  // a line: second differences vanish
  }
  spec.measured = {m};
  EXPECT_NEAR(NoiseFloorCost(spec), 0, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// A synthetic calibration: one experiment "e", channels sampled at `times`, a model per channel.

struct Synthetic {
  Spec spec;
  std::vector<double> times;
  std::vector<std::string> columns;
  // y of channel c at t for parameter values
  std::function<double(const std::vector<double>&, size_t, double)> model;
  std::vector<std::vector<double>> measured;  // per channel
  std::vector<ResidualBlock> blocks;
  std::vector<double> scales;  // BlockScales(blocks)

  Synthetic(std::vector<Parameter> parameters, std::vector<std::string> channel_names,
            size_t samples, double duration) {
    spec = OneExperiment("e", std::move(parameters));
    columns = std::move(channel_names);
    for (size_t i = 0; i < samples; ++i)
      times.push_back(duration * static_cast<double>(i) / static_cast<double>(samples - 1));
  }

  // Measurements: the model at `truth` plus white noise of sigma[c] per channel.
  void Measure(const std::vector<double>& truth, const std::vector<double>& sigma, uint64_t seed) {
    std::mt19937_64 random(seed);
    std::normal_distribution<double> noise(0, 1);
    measured.assign(columns.size(), {});
    blocks.clear();
    size_t begin = 0;
    for (size_t c = 0; c < columns.size(); ++c) {
      for (double t : times) measured[c].push_back(model(truth, c, t) + sigma[c] * noise(random));
      const auto [lo, hi] = std::minmax_element(measured[c].begin(), measured[c].end());
      blocks.push_back({0, columns[c], "m", 1, *hi - *lo, begin, times.size()});
      begin += times.size();
    }
    scales = BlockScales(blocks);
  }

  size_t Rows() const { return columns.size() * times.size(); }

  std::vector<double> Values(const std::vector<double>& unit) const {
    std::vector<double> v;
    for (size_t j = 0; j < unit.size(); ++j) v.push_back(spec.parameters[j].FromUnit(unit[j]));
    return v;
  }
  std::vector<double> Units(const std::vector<double>& values) const {
    std::vector<double> u;
    for (size_t j = 0; j < values.size(); ++j) u.push_back(spec.parameters[j].ToUnit(values[j]));
    return u;
  }

  // simulated - measured, channel by channel
  Residuals Raw(const std::vector<double>& values) const {
    Residuals r;
    for (size_t c = 0; c < columns.size(); ++c)
      for (size_t i = 0; i < times.size(); ++i)
        r.push_back(model(values, c, times[i]) - measured[c][i]);
    return r;
  }
  // as the evaluator's: the squares sum to the cost squared
  Residuals Weighted(const std::vector<double>& values) const {
    Residuals r = Raw(values);
    for (size_t b = 0; b < blocks.size(); ++b)
      for (size_t i = 0; i < blocks[b].samples; ++i) r[blocks[b].begin + i] *= std::sqrt(scales[b]);
    return r;
  }
  BatchResiduals WeightedBatch() const {
    return [this](const std::vector<std::vector<double>>& units) {
      std::vector<std::optional<Residuals>> out;
      for (const auto& u : units) out.emplace_back(Weighted(Values(u)));
      return out;
    };
  }
  BatchResiduals RawBatch() const {
    return [this](const std::vector<std::vector<double>>& units) {
      std::vector<std::optional<Residuals>> out;
      for (const auto& u : units) out.emplace_back(Raw(Values(u)));
      return out;
    };
  }

  // The cost of Cost(CompareRecording(...)): sqrt of the weighted mean of (rms / range)^2.
  double CostOf(const std::vector<double>& values) const {
    const Residuals r = Raw(values);
    double sum = 0, weights = 0;
    for (const auto& b : blocks) {
      double square = 0;
      for (size_t i = 0; i < b.samples; ++i) square += r[b.begin + i] * r[b.begin + i];
      sum += b.weight * square / static_cast<double>(b.samples) / (b.range * b.range);
      weights += b.weight;
    }
    return std::sqrt(sum / weights);
  }

  // The uncertainty at `values`: the raw residuals' Jacobian (central, step 1e-4) and Analyse.
  Uncertainty AnalyseAt(const std::vector<double>& values,
                        const UncertaintyOptions& options = {}) const {
    const std::vector<double> unit = Units(values);
    const Residuals base = Raw(values);
    const Eigen::MatrixXd j =
        Jacobian(RawBatch(), unit, base, std::vector<double>(unit.size(), 1e-4), true);
    return Analyse(spec, j, base, blocks, values, options);
  }
};

const Parameter kA{"A", 0.5, 5, false};
const Parameter kTau{"tau", 0.05, 2, true};

double Decay(const std::vector<double>& v, size_t, double t) { return v[0] * std::exp(-t / v[1]); }

RefineOptions Options(size_t n, unsigned iterations = 50) {
  RefineOptions o;
  o.max_iterations = iterations;
  o.central = true;
  o.steps.assign(n, 1e-4);
  return o;
}

TEST(BlockScales, MakeTheSquaredResidualsSumToTheCostSquared) {
  Synthetic s({kA, kTau}, {"y", "z"}, 50, 2);
  s.model = [](const std::vector<double>& v, size_t c, double t) {
    return c == 0 ? Decay(v, c, t) : 3 + 0.5 * t * v[0];
  };
  s.Measure({2, 0.5}, {0.05, 0.05}, 11);
  s.blocks[1].weight = 4;
  s.scales = BlockScales(s.blocks);
  EXPECT_DOUBLE_EQ(s.scales[1], 4.0 / (5 * s.blocks[1].range * s.blocks[1].range * 50));
  const Residuals w = s.Weighted({2.4, 0.4});
  double square = 0;
  for (double r : w) square += r * r;
  EXPECT_NEAR(std::sqrt(square), s.CostOf({2.4, 0.4}), 1e-12);
  // a block without samples has no weight, nor does it share in the others'
  auto blocks = s.blocks;
  blocks.push_back({0, "none", "m", 7, 1, 100, 0});
  const auto scales = BlockScales(blocks);
  EXPECT_EQ(scales[2], 0);
  EXPECT_DOUBLE_EQ(scales[0], s.scales[0]);
}

TEST(Jacobian, CentralDifferencesMatchTheAnalyticDerivative) {
  Synthetic s({kA, kTau}, {"y"}, 200, 2);
  s.model = Decay;
  s.Measure({2, 0.5}, {0.0}, 1);
  const std::vector<double> values = {1.7, 0.35};
  const std::vector<double> unit = s.Units(values);
  const double dvalue_a = kA.upper - kA.lower,
               dtau_du = values[1] * std::log(kTau.upper / kTau.lower);
  const double w = std::sqrt(s.scales[0]);
  Eigen::MatrixXd analytic(200, 2);
  for (size_t i = 0; i < 200; ++i) {
    const double t = s.times[i], e = std::exp(-t / values[1]);
    analytic(static_cast<Eigen::Index>(i), 0) = w * e * dvalue_a;
    analytic(static_cast<Eigen::Index>(i), 1) =
        w * values[0] * e * t / (values[1] * values[1]) * dtau_du;
  }
  const Residuals base = s.Weighted(values);
  const Eigen::MatrixXd central = Jacobian(s.WeightedBatch(), unit, base, {1e-5, 1e-5}, true);
  ASSERT_EQ(central.rows(), 200);
  ASSERT_EQ(central.cols(), 2);
  for (Eigen::Index j = 0; j < 2; ++j) {
    const double scale = analytic.col(j).cwiseAbs().maxCoeff();
    EXPECT_LT((central.col(j) - analytic.col(j)).cwiseAbs().maxCoeff(), 1e-6 * scale) << j;
  }
  // forward differences: first order in the step
  const Eigen::MatrixXd forward = Jacobian(s.WeightedBatch(), unit, base, {1e-5, 1e-5}, false);
  for (Eigen::Index j = 0; j < 2; ++j) {
    const double scale = analytic.col(j).cwiseAbs().maxCoeff();
    const double error = (forward.col(j) - analytic.col(j)).cwiseAbs().maxCoeff();
    EXPECT_LT(error, 1e-3 * scale) << j;
    if (j == 1) {
      EXPECT_GT(error, 1e-7 * scale);  // tau is not linear in the unit: not exact
    }
  }
  // at the upper bound the step is taken the other way (one-sided), no point leaves [0, 1]
  std::vector<double> at_bound = unit;
  at_bound[0] = 1;
  std::vector<std::vector<double>> asked;
  const BatchResiduals spy = [&](const std::vector<std::vector<double>>& points) {
    asked.insert(asked.end(), points.begin(), points.end());
    return s.WeightedBatch()(points);
  };
  const Eigen::MatrixXd edge =
      Jacobian(spy, at_bound, s.Weighted(s.Values(at_bound)), {1e-5, 1e-5}, true);
  EXPECT_EQ(asked.size(), 3u);  // one for A (one-sided), two for tau
  for (const auto& p : asked)
    for (double u : p) {
      EXPECT_GE(u, 0);
      EXPECT_LE(u, 1);
    }
  const double e_scale = std::abs(w * dvalue_a);  // d/du of A e^(-t/tau) at t = 0
  EXPECT_NEAR(edge(0, 0), e_scale, 1e-6 * e_scale);
}

TEST(Jacobian, AFaultedPointThrows) {
  const BatchResiduals faulty = [](const std::vector<std::vector<double>>& points) {
    std::vector<std::optional<Residuals>> out(points.size(), Residuals{1.0, 2.0});
    out[1].reset();
    return out;
  };
  EXPECT_THROW(Jacobian(faulty, {0.5, 0.5}, {1.0, 2.0}, {1e-4, 1e-4}, false), std::runtime_error);
}

TEST(Jacobian, AFaultedSideOfACentralDifferenceLeavesTheOtherSide) {
  // r = (3 u0 + u1^2, u0 u1) at (0.5, 0.25): d/du0 = (3, 0.25), d/du1 = (0.5, 0.5); the point
  // below u0 faults, and both points of u1 in the second call
  const auto r = [](const std::vector<double>& u) {
    return Residuals{3 * u[0] + u[1] * u[1], u[0] * u[1]};
  };
  const std::vector<double> unit = {0.5, 0.25};
  const double h = 1e-3;
  int calls = 0;
  const BatchResiduals faulty = [&](const std::vector<std::vector<double>>& points) {
    ++calls;
    std::vector<std::optional<Residuals>> out;
    for (const auto& p : points) {
      const bool below_u0 = p[0] < unit[0];
      const bool moves_u1 = p[1] != unit[1];
      if (below_u0 || (calls == 2 && moves_u1))
        out.emplace_back();
      else
        out.emplace_back(r(p));
    }
    return out;
  };
  const Eigen::MatrixXd j = Jacobian(faulty, unit, r(unit), {h, h}, true);
  EXPECT_NEAR(j(0, 0), 3, 1e-9);  // forward from the point above: exact for a line
  EXPECT_NEAR(j(1, 0), 0.25, 1e-9);
  EXPECT_NEAR(j(0, 1), 0.5, 1e-9);  // central
  EXPECT_NEAR(j(1, 1), 0.5, 1e-9);
  EXPECT_THROW(Jacobian(faulty, unit, r(unit), {h, h}, true), std::runtime_error);
}

TEST(Refine, FindsTheTruthOfNoiseFreeData) {
  Synthetic s({kA, kTau}, {"y"}, 200, 2);
  s.model = Decay;
  const std::vector<double> truth = {2, 0.5};
  s.Measure(truth, {0.0}, 1);
  const std::vector<double> start = s.Units({truth[0] * 1.3, truth[1] * 1.3});
  unsigned callbacks = 0;
  RefineOptions options = Options(2);
  options.on_iteration = [&](const RefineProgress& p) {
    ++callbacks;
    EXPECT_EQ(p.unit.size(), 2u);
    EXPECT_GE(p.cost, 0);
  };
  const RefineResult r = Refine(s.WeightedBatch(), start, s.Rows(), options);
  const std::vector<double> found = s.Values(r.unit);
  std::printf("refine: %s (%u iterations, %llu points), A %.9f tau %.9f\n", r.reason.c_str(),
              r.iterations, static_cast<unsigned long long>(r.evaluations), found[0], found[1]);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.reason.rfind("converged:", 0), 0u) << r.reason;
  EXPECT_FALSE(r.interrupted);
  EXPECT_NEAR(found[0], truth[0], 1e-6 * truth[0]);
  EXPECT_NEAR(found[1], truth[1], 1e-6 * truth[1]);
  // the costs are the evaluator's: the start's is that of the start point, the end's near 0
  EXPECT_NEAR(r.start_cost, s.CostOf(s.Values(start)), 1e-12);
  EXPECT_GT(r.start_cost, 0.05);
  EXPECT_LT(r.cost, 1e-7);
  EXPECT_GT(r.iterations, 0u);
  EXPECT_GE(callbacks, r.iterations);
  // a central Jacobian of 2 parameters (4 points) at least, and a point per iteration
  EXPECT_GE(r.evaluations, 4u + r.iterations);
}

TEST(Refine, StaysInTheBoxWhenTheBestFitIsBeyondIt) {
  // the truth A = 6 is above the bound 5: the best fit in the box is on its face
  Synthetic s({kA, kTau}, {"y"}, 200, 2);
  s.model = Decay;
  s.Measure({6, 0.5}, {0.0}, 1);
  RefineOptions options = Options(2);
  bool outside = false;
  options.on_iteration = [&](const RefineProgress& p) {
    for (double u : p.unit) outside = outside || u < 0 || u > 1;
  };
  const RefineResult r = Refine(s.WeightedBatch(), s.Units({3, 0.4}), s.Rows(), options);
  std::printf("beyond the box: %s, unit %.9f %.9f\n", r.reason.c_str(), r.unit[0], r.unit[1]);
  ASSERT_EQ(r.unit.size(), 2u);
  EXPECT_GE(r.unit[0], 0);
  EXPECT_LE(r.unit[0], 1);
  EXPECT_NEAR(r.unit[0], 1, 1e-6);
  EXPECT_GE(r.unit[1], 0);
  EXPECT_LE(r.unit[1], 1);
  // the cost reported is that of the point returned
  EXPECT_NEAR(r.cost, s.CostOf(s.Values(r.unit)), 1e-9);
  EXPECT_LT(r.cost, r.start_cost);
  EXPECT_FALSE(outside) << "a progress report with a point outside [0, 1]";
}

TEST(Refine, ReportsAnExhaustedBudgetAndAnInterruption) {
  Synthetic s({kA, kTau}, {"y"}, 200, 2);
  s.model = Decay;
  s.Measure({2, 0.5}, {0.0}, 1);
  const std::vector<double> start = s.Units({0.6, 1.8});
  const RefineResult budget = Refine(s.WeightedBatch(), start, s.Rows(), Options(2, 1));
  EXPECT_FALSE(budget.converged);
  EXPECT_EQ(budget.reason.rfind("stopped: budget of 1 iterations spent", 0), 0u) << budget.reason;
  EXPECT_LE(budget.cost, budget.start_cost);

  RefineOptions options = Options(2);
  options.interrupted = [] { return true; };
  const RefineResult stopped = Refine(s.WeightedBatch(), start, s.Rows(), options);
  EXPECT_TRUE(stopped.interrupted);
  EXPECT_FALSE(stopped.converged);
  EXPECT_EQ(stopped.reason.rfind("stopped: interrupted after", 0), 0u) << stopped.reason;
}

// ---------------------------------------------------------------------------------------------
// Uncertainty against closed forms

TEST(Analyse, OneOffsetOverTwoChannelsHasTheWeightedMeansVariance) {
  // y = c in two channels of 100 and 300 samples, weights 1 and 3, ranges 1 and 4; residuals of
  // +-0.01 and +-0.1: the estimate is the weighted mean, of variance sum(n a^2 s^2) / (sum n a)^2
  Spec spec = OneExperiment("e", {{"c", -1, 1, false}});
  const size_t n1 = 100, n2 = 300;
  std::vector<ResidualBlock> blocks = {{0, "p", "m", 1, 1, 0, n1}, {0, "q", "m", 3, 4, n1, n2}};
  std::vector<double> residuals;
  for (size_t i = 0; i < n1; ++i) residuals.push_back(i % 2 ? 0.01 : -0.01);
  for (size_t i = 0; i < n2; ++i) residuals.push_back(i % 2 ? 0.1 : -0.1);
  const Eigen::MatrixXd j = Eigen::MatrixXd::Constant(n1 + n2, 1, 2.0);  // d residual / d unit
  const Uncertainty u = Analyse(spec, j, residuals, blocks, {0.25}, {});
  const double dof = 1 - 1.0 / (n1 + n2);
  const double v1 = 0.01 * 0.01 / dof, v2 = 0.1 * 0.1 / dof;
  const double a1 = 1.0 / (4 * 1 * n1), a2 = 3.0 / (4 * 16 * n2);
  const double sigma = std::sqrt(n1 * a1 * a1 * v1 + n2 * a2 * a2 * v2) / (n1 * a1 + n2 * a2);
  ASSERT_EQ(u.parameters.size(), 1u);
  ASSERT_EQ(u.noise.size(), 2u);
  EXPECT_EQ(u.residuals, n1 + n2);
  EXPECT_NEAR(u.noise[0].sigma, std::sqrt(v1), 1e-15);
  EXPECT_NEAR(u.noise[1].sigma, std::sqrt(v2), 1e-14);
  EXPECT_EQ(u.noise[1].experiment, "e");
  EXPECT_EQ(u.noise[1].column, "q");
  EXPECT_EQ(u.noise[1].samples, n2);
  const auto& c = u.parameters[0];
  EXPECT_TRUE(c.determined);
  EXPECT_DOUBLE_EQ(c.value, 0.25);
  EXPECT_NEAR(c.sigma, sigma, 1e-12 * sigma);
  EXPECT_NEAR(c.lower95, 0.25 - 1.96 * sigma, 1e-12);
  EXPECT_NEAR(c.upper95, 0.25 + 1.96 * sigma, 1e-12);
  EXPECT_NEAR(u.covariance(0, 0), sigma * sigma, 1e-12 * sigma * sigma);
  EXPECT_NEAR(u.correlation(0, 0), 1, 1e-12);
  // sqrt(a) |J| per channel: p 2 sqrt(100 / 400) = 1, q 2 sqrt(300 * 3 / 19200) = 0.43
  EXPECT_EQ(c.most_sensitive_channel, "e: p");
}

TEST(Analyse, AParameterActingInStepsIsKnownToAStepAtBest) {
  // one channel that moves exactly with the parameter, residuals of +-1e-9: without a
  // resolution the interval is next to nothing; with one of 1 ms, sigma is 1 ms / sqrt(12)
  Spec spec = OneExperiment("e", {{"command_delay:m", 0, 0.05, false}});
  spec.parameters[0].kind = ParameterKind::kCommandDelay;
  const size_t n = 200;
  std::vector<ResidualBlock> blocks = {{0, "p", "rad", 1, 1, 0, n}};
  std::vector<double> residuals;
  for (size_t i = 0; i < n; ++i) residuals.push_back(i % 2 ? 1e-9 : -1e-9);
  const Eigen::MatrixXd j = Eigen::MatrixXd::Constant(n, 1, 1.0);
  const double fine = Analyse(spec, j, residuals, blocks, {0.02}, {}).parameters[0].sigma;
  EXPECT_LT(fine, 1e-8);
  spec.parameters[0].resolution = 0.001;
  const auto u = Analyse(spec, j, residuals, blocks, {0.02}, {}).parameters[0];
  EXPECT_NEAR(u.sigma, std::sqrt(0.001 * 0.001 / 12 + fine * fine), 1e-12);
  EXPECT_LT(u.lower95, 0.02 - 0.0005);
  EXPECT_GT(u.upper95, 0.02 + 0.0005);
}

TEST(Analyse, AStraightLineHasTheOrdinaryLeastSquaresCovariance) {
  // y = a + b t, a linear in [-1, 1], b log-scale in [0.1, 10]: one channel, so the weights
  // cancel and the covariance is s^2 (X'X)^-1 in the parameters' units whatever the scaling
  Spec spec = OneExperiment("line", {{"a", -1, 1, false}, {"b", 0.1, 10, true}});
  const double a = 0.3, b = 2;
  const size_t m = 41;
  Eigen::MatrixXd x(m, 2), j(m, 2);
  std::vector<double> residuals;
  double square = 0;
  for (size_t i = 0; i < m; ++i) {
    const double t = 0.5 + 0.1 * static_cast<double>(i);
    const auto r = static_cast<Eigen::Index>(i);
    x(r, 0) = 1;
    x(r, 1) = t;
    j(r, 0) = 2;                        // d(a)/d(unit) = upper - lower
    j(r, 1) = t * b * std::log(100.0);  // d(b)/d(unit) = b ln(upper / lower)
    residuals.push_back(0.05 * std::sin(3.0 * static_cast<double>(i)));
    square += residuals.back() * residuals.back();
  }
  const std::vector<ResidualBlock> blocks = {{0, "y", "m", 1, 2.5, 0, m}};
  const Uncertainty u = Analyse(spec, j, residuals, blocks, {a, b}, {});
  const double s2 = square / static_cast<double>(m - 2);
  const Eigen::Matrix2d expected = s2 * (x.transpose() * x).inverse();
  EXPECT_NEAR(u.noise[0].sigma, std::sqrt(s2), 1e-14);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 2; ++c)
      EXPECT_NEAR(u.covariance(r, c), expected(r, c), 1e-10 * expected.cwiseAbs().maxCoeff())
          << r << "," << c;
  const double sum_t = x.col(1).sum(), sum_t2 = x.col(1).squaredNorm();
  EXPECT_NEAR(u.correlation(0, 1), -sum_t / std::sqrt(static_cast<double>(m) * sum_t2), 1e-10);
  EXPECT_NEAR(u.correlation(1, 0), u.correlation(0, 1), 1e-15);
  EXPECT_NEAR(u.parameters[1].sigma, std::sqrt(expected(1, 1)), 1e-10);
  EXPECT_NEAR(u.parameters[1].upper95 - u.parameters[1].lower95,
              2 * 1.96 * std::sqrt(expected(1, 1)), 1e-10);
}

// ---------------------------------------------------------------------------------------------
// Uncertainty of the synthetic decay

TEST(Analyse, NinetyFivePercentIntervalsCoverTheTruth) {
  const std::vector<double> truth = {2, 0.5};
  const double sigma = 0.02;
  int covered_a = 0, covered_tau = 0;
  double noise_sum = 0;
  const int seeds = 20;
  for (int seed = 1; seed <= seeds; ++seed) {
    Synthetic s({kA, kTau}, {"y"}, 200, 2);
    s.model = Decay;
    s.Measure(truth, {sigma}, static_cast<uint64_t>(seed));
    const RefineResult r =
        Refine(s.WeightedBatch(), s.Units({truth[0] * 1.1, truth[1] * 0.9}), s.Rows(), Options(2));
    EXPECT_TRUE(r.converged) << seed << ": " << r.reason;
    const std::vector<double> values = s.Values(r.unit);
    const Uncertainty u = s.AnalyseAt(values);
    ASSERT_EQ(u.parameters.size(), 2u);
    ASSERT_EQ(u.noise.size(), 1u);
    EXPECT_TRUE(u.parameters[0].determined);
    EXPECT_TRUE(u.parameters[1].determined);
    EXPECT_TRUE(u.warnings.empty()) << seed << ": " << AllWarnings(u);
    const auto inside = [](const ParameterUncertainty& p, double x) {
      return p.lower95 <= x && x <= p.upper95;
    };
    covered_a += inside(u.parameters[0], truth[0]);
    covered_tau += inside(u.parameters[1], truth[1]);
    noise_sum += u.noise[0].sigma;
    if (seed == 1)
      std::printf("seed 1: A %.4f +- %.4f, tau %.4f +- %.4f, correlation %.3f\n", values[0],
                  1.96 * u.parameters[0].sigma, values[1], 1.96 * u.parameters[1].sigma,
                  u.correlation(0, 1));
  }
  const double mean_noise = noise_sum / seeds;
  std::printf("coverage of the 95 %% intervals: A %d/%d, tau %d/%d; mean noise %.5f (true %.3f)\n",
              covered_a, seeds, covered_tau, seeds, mean_noise, sigma);
  EXPECT_GE(covered_a, 17);
  EXPECT_GE(covered_tau, 17);
  EXPECT_NEAR(mean_noise, sigma, 0.2 * sigma);
}

TEST(Analyse, TellsChannelsOfDifferentNoiseApart) {
  Synthetic s({kA, kTau}, {"quiet", "loud"}, 200, 2);
  s.model = [](const std::vector<double>& v, size_t c, double t) {
    const double e = std::exp(-t / v[1]);
    return c == 0 ? v[0] * e : v[0] * (1 - e);
  };
  const std::vector<double> truth = {2, 0.5};
  s.Measure(truth, {0.01, 0.1}, 5);
  const RefineResult r = Refine(s.WeightedBatch(), s.Units({2.5, 0.4}), s.Rows(), Options(2));
  ASSERT_TRUE(r.converged) << r.reason;
  const Uncertainty u = s.AnalyseAt(s.Values(r.unit));
  ASSERT_EQ(u.noise.size(), 2u);
  std::printf("noise estimates: quiet %.5f (0.01), loud %.5f (0.1)\n", u.noise[0].sigma,
              u.noise[1].sigma);
  EXPECT_EQ(u.noise[0].column, "quiet");
  EXPECT_EQ(u.noise[1].column, "loud");
  EXPECT_NEAR(u.noise[0].sigma, 0.01, 0.25 * 0.01);
  EXPECT_NEAR(u.noise[1].sigma, 0.1, 0.25 * 0.1);
  EXPECT_EQ(u.noise[0].samples, 200u);
  for (const auto& p : u.parameters) EXPECT_TRUE(p.determined);
}

TEST(Analyse, AParameterNoChannelDependsOnIsNotDetermined) {
  Synthetic s({kA, kTau, {"ghost", 0, 1, false}}, {"y"}, 200, 2);
  s.model = Decay;  // ignores v[2]
  const std::vector<double> truth = {2, 0.5, 0.3};
  s.Measure(truth, {0.02}, 7);
  const Uncertainty u = s.AnalyseAt(truth);
  ASSERT_EQ(u.parameters.size(), 3u);
  const auto& ghost = u.parameters[2];
  EXPECT_FALSE(ghost.determined);
  EXPECT_EQ(ghost.lower95, -kInf);
  EXPECT_EQ(ghost.upper95, kInf);
  EXPECT_TRUE(std::isnan(u.covariance(2, 2)));
  EXPECT_TRUE(std::isnan(u.correlation(0, 2)));
  EXPECT_FALSE(WarningWith(u, {"ghost", "no channel"}).empty()) << AllWarnings(u);
  // the others are as without it (but for the degrees of freedom: 200 - 3 instead of 200 - 2)
  Synthetic two({kA, kTau}, {"y"}, 200, 2);
  two.model = Decay;
  two.Measure({2, 0.5}, {0.02}, 7);
  const Uncertainty without = two.AnalyseAt({2, 0.5});
  for (size_t j = 0; j < 2; ++j) {
    EXPECT_TRUE(u.parameters[j].determined);
    EXPECT_NEAR(u.parameters[j].sigma, without.parameters[j].sigma,
                1e-2 * without.parameters[j].sigma);
  }
  EXPECT_EQ(WarningWith(u, {"A:"}), "");
  EXPECT_EQ(WarningWith(u, {"tau:"}), "");
}

TEST(Analyse, OnlyTheProductOfTwoFactorsIsDetermined) {
  // y = a b exp(-t): a and b act alike on every sample
  Synthetic s({{"a", 0.5, 5, true}, {"b", 0.2, 20, true}}, {"y"}, 200, 2);
  s.model = [](const std::vector<double>& v, size_t, double t) {
    return v[0] * v[1] * std::exp(-t);
  };
  const std::vector<double> truth = {2, 1.5};
  s.Measure(truth, {0.02}, 9);
  const Uncertainty u = s.AnalyseAt(truth);
  ASSERT_EQ(u.parameters.size(), 2u);
  const double rho = u.correlation(0, 1);
  for (const auto& p : u.parameters)
    EXPECT_TRUE(!p.determined || std::abs(rho) > 0.95)
        << "reported determined, sigma " << p.sigma << ", correlation " << rho;
  const std::string warnings = AllWarnings(u);
  EXPECT_TRUE(!WarningWith(u, {"a", "b", "correlated"}).empty() ||
              !WarningWith(u, {"a", "b", "only a combination"}).empty())
      << warnings;
  std::printf("product: determined %d %d, warnings:\n%s", u.parameters[0].determined,
              u.parameters[1].determined, warnings.c_str());
}

TEST(Analyse, AWeaklyDeterminedParameterWarnsOfItsWideInterval) {
  // k moves y only a little and z a little more, far less than the noise
  Synthetic s({kA, kTau, {"k", 0.5, 5, false}}, {"y", "z"}, 200, 2);
  s.model = [](const std::vector<double>& v, size_t c, double t) {
    return c == 0 ? v[0] * std::exp(-t / v[1]) + 2e-4 * v[2] * t : 1 + 2e-3 * v[2] * t;
  };
  const std::vector<double> truth = {2, 0.5, 2};
  s.Measure(truth, {0.02, 0.02}, 13);
  UncertaintyOptions options;
  options.max_relative_interval = 0.1;
  const Uncertainty u = s.AnalyseAt(truth, options);
  const auto& k = u.parameters[2];
  EXPECT_TRUE(k.determined);
  EXPECT_GT(1.96 * k.sigma, 0.1 * truth[2]);
  EXPECT_EQ(k.most_sensitive_channel, "e: z");
  const std::string w = WarningWith(u, {"k:", "95 % interval", "e: z"});
  EXPECT_FALSE(w.empty()) << AllWarnings(u);
  std::printf("%s", w.c_str());
  // A and tau are pinned: no warning names them
  EXPECT_EQ(WarningWith(u, {"A:"}), "") << AllWarnings(u);
  EXPECT_EQ(WarningWith(u, {"tau:"}), "") << AllWarnings(u);
  // a looser threshold: no warning at all
  options.max_relative_interval = 1.96 * k.sigma / truth[2] * 1.01;
  EXPECT_TRUE(s.AnalyseAt(truth, options).warnings.empty())
      << AllWarnings(s.AnalyseAt(truth, options));
}

TEST(Analyse, NearlyProportionalEffectsWarnOfTheirCorrelation) {
  // y: a and b act almost alike; z (noisy, weighted little) tells them apart
  Synthetic s({{"a", 0.5, 5, false}, {"b", 0.5, 5, false}}, {"y", "z"}, 200, 2);
  s.model = [](const std::vector<double>& v, size_t c, double t) {
    return c == 0 ? v[0] * std::exp(-t) + v[1] * std::exp(-1.1 * t)
                  : v[0] * std::sin(3 * t) + v[1] * std::cos(3 * t);
  };
  const std::vector<double> truth = {2, 1.5};
  s.Measure(truth, {0.02, 0.5}, 17);
  s.blocks[1].weight = 1e-3;
  s.scales = BlockScales(s.blocks);
  const Uncertainty u = s.AnalyseAt(truth);
  const double rho = u.correlation(0, 1);
  std::printf("correlation %.5f\n%s", rho, AllWarnings(u).c_str());
  EXPECT_TRUE(u.parameters[0].determined);
  EXPECT_TRUE(u.parameters[1].determined);
  EXPECT_GT(std::abs(rho), 0.95);
  EXPECT_FALSE(WarningWith(u, {"a and b are correlated", "e: z tells them apart best"}).empty())
      << AllWarnings(u);
  UncertaintyOptions loose;
  loose.max_correlation = std::min(1.0, std::abs(rho) * 1.0001);
  loose.max_relative_interval = 1e9;
  EXPECT_TRUE(s.AnalyseAt(truth, loose).warnings.empty()) << AllWarnings(s.AnalyseAt(truth, loose));
}

TEST(Analyse, NoParameterMovingAnythingIsNotDeterminedAndDoesNotCrash) {
  Synthetic s({{"ghost", 0, 1, false}}, {"y"}, 50, 1);
  s.model = [](const std::vector<double>&, size_t, double t) { return t; };
  s.Measure({0.5}, {0.01}, 3);
  const Uncertainty u = s.AnalyseAt({0.5});
  ASSERT_EQ(u.parameters.size(), 1u);
  EXPECT_FALSE(u.parameters[0].determined);
  EXPECT_EQ(u.parameters[0].upper95, kInf);
  EXPECT_FALSE(WarningWith(u, {"ghost", "no channel"}).empty()) << AllWarnings(u);
  EXPECT_NEAR(u.noise[0].sigma, 0.01, 0.3 * 0.01);
}

}  // namespace
}  // namespace caliper::calibration
