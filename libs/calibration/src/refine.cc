#include "caliper/calibration/refine.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>

namespace caliper::calibration {

namespace {

// The points of a finite-difference Jacobian at `unit`: per column one (forward) or two
// (central) points, with the signed steps taken.
struct Stencil {
  std::vector<std::vector<double>> points;
  std::vector<std::pair<double, double>> steps;  // per column: (plus, minus); minus 0 for forward
};

Stencil MakeStencil(const std::vector<double>& unit, const std::vector<double>& steps,
                    bool central) {
  Stencil s;
  for (size_t j = 0; j < unit.size(); ++j) {
    const double h = steps[j];
    // central when both sides are inside [0, 1], else one-sided on the side that is
    const bool up = unit[j] + h <= 1, down = unit[j] - h >= 0;
    const double plus = up ? h : -h;
    const double minus = central && up && down ? -h : 0;
    auto p = unit;
    p[j] += plus;
    s.points.push_back(p);
    if (minus != 0) {
      auto q = unit;
      q[j] += minus;
      s.points.push_back(q);
    }
    s.steps.emplace_back(plus, minus);
  }
  return s;
}

Eigen::MatrixXd Assemble(const Stencil& s, const std::vector<std::optional<Residuals>>& got,
                         const Residuals& base) {
  const Eigen::Index m = static_cast<Eigen::Index>(base.size());
  Eigen::MatrixXd j(m, static_cast<Eigen::Index>(s.steps.size()));
  size_t k = 0;
  for (size_t c = 0; c < s.steps.size(); ++c) {
    const auto& [plus, minus] = s.steps[c];
    const auto usable = [&](const std::optional<Residuals>& r) {
      return r && r->size() == base.size();
    };
    const std::optional<Residuals>& rp = got[k++];
    static const std::optional<Residuals> kNone;
    const std::optional<Residuals>& rm = minus != 0 ? got[k++] : kNone;
    // a faulted side of a central difference: the other side alone (one-sided)
    const Residuals* high = usable(rp) ? &*rp : &base;
    const Residuals* low = usable(rm) ? &*rm : &base;
    const double h_high = usable(rp) ? plus : 0, h_low = usable(rm) ? minus : 0;
    if (h_high == h_low)
      throw std::runtime_error("a finite-difference point of the Jacobian faulted");
    for (Eigen::Index i = 0; i < m; ++i)
      j(i, static_cast<Eigen::Index>(c)) =
          ((*high)[static_cast<size_t>(i)] - (*low)[static_cast<size_t>(i)]) / (h_high - h_low);
  }
  return j;
}

// The residuals for Ceres, with our Jacobian: one batch per evaluation (the point itself and,
// when Ceres asks for the Jacobian, every finite-difference point of it at once).
class CostFunction : public ceres::DynamicCostFunction {
 public:
  CostFunction(const BatchResiduals& batch, size_t parameters, size_t residuals,
               const RefineOptions& options)
      : batch_(batch), options_(options) {
    AddParameterBlock(static_cast<int>(parameters));
    SetNumResiduals(static_cast<int>(residuals));
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const size_t n = static_cast<size_t>(parameter_block_sizes()[0]);
    // the box [0, 1]^n by clamping: outside it the residuals are those at its face (Ceres'
    // bounds would add a line search with a whole Jacobian per trial point)
    std::vector<double> x(parameters[0], parameters[0] + n);
    for (double& v : x) v = std::clamp(v, 0.0, 1.0);
    std::optional<Residuals> base;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (x == cached_point_) base = cached_;
    }
    Stencil stencil;
    std::vector<std::vector<double>> points;
    if (!base) points.push_back(x);
    if (jacobians && jacobians[0]) {
      stencil = MakeStencil(x, options_.steps, options_.central);
      points.insert(points.end(), stencil.points.begin(), stencil.points.end());
    }
    std::vector<std::optional<Residuals>> got;
    if (!points.empty()) {
      got = batch_(points);
      evaluations_ += points.size();
    }
    if (!base) {
      base = got.front();
      got.erase(got.begin());
      if (!base) return false;  // faulted: Ceres shrinks its step
      std::lock_guard<std::mutex> lock(mutex_);
      cached_point_ = x;
      cached_ = *base;
    }
    if (base->size() != static_cast<size_t>(num_residuals())) return false;
    std::copy(base->begin(), base->end(), residuals);
    if (jacobians && jacobians[0]) {
      Eigen::MatrixXd j;
      try {
        j = Assemble(stencil, got, *base);
      } catch (const std::runtime_error&) {
        return false;
      }
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[0], j.rows(), j.cols()) = j;
    }
    return true;
  }

  uint64_t evaluations() const { return evaluations_; }

 private:
  const BatchResiduals& batch_;
  const RefineOptions& options_;
  mutable std::mutex mutex_;
  mutable std::vector<double> cached_point_;
  mutable Residuals cached_;
  mutable uint64_t evaluations_ = 0;
};

class Callback : public ceres::IterationCallback {
 public:
  Callback(const RefineOptions& options, const std::vector<double>& x, const CostFunction& f)
      : options_(options), x_(x), f_(f) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (options_.on_iteration) {
      RefineProgress p;
      p.iteration = static_cast<unsigned>(summary.iteration);
      p.cost = std::sqrt(2 * summary.cost);
      p.evaluations = f_.evaluations();
      p.unit = x_;  // Ceres' point may lie beyond the box; the residuals are those of its clamp
      for (double& v : p.unit) v = std::clamp(v, 0.0, 1.0);
      options_.on_iteration(p);
    }
    if (options_.interrupted && options_.interrupted()) {
      interrupted = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool interrupted = false;

 private:
  const RefineOptions& options_;
  const std::vector<double>& x_;
  const CostFunction& f_;
};

}  // namespace

Eigen::MatrixXd Jacobian(const BatchResiduals& batch, const std::vector<double>& unit,
                         const Residuals& base, const std::vector<double>& steps, bool central) {
  const Stencil s = MakeStencil(unit, steps, central);
  return Assemble(s, batch(s.points), base);
}

RefineResult Refine(const BatchResiduals& batch, const std::vector<double>& start, size_t residuals,
                    const RefineOptions& options) {
  RefineResult out;
  std::vector<double> x = start;
  const size_t n = x.size();
  auto* f = new CostFunction(batch, n, residuals, options);  // owned by the problem
  ceres::Problem problem;
  problem.AddResidualBlock(f, nullptr, x.data());
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = static_cast<int>(options.max_iterations);
  so.function_tolerance = 1e-8;  // the simulator's round-off makes smaller changes noise
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-8;
  so.num_threads = 1;  // the parallelism is in the batches
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.update_state_every_iteration = true;  // the callback sees the point
  Callback callback(options, x, *f);
  so.callbacks.push_back(&callback);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  out.unit = x;
  for (double& v : out.unit) v = std::clamp(v, 0.0, 1.0);
  out.start_cost = std::sqrt(2 * summary.initial_cost);
  out.cost = std::sqrt(2 * summary.final_cost);
  out.iterations =
      static_cast<unsigned>(summary.iterations.size() > 0 ? summary.iterations.size() - 1 : 0);
  out.evaluations = f->evaluations();
  out.interrupted = callback.interrupted;
  if (callback.interrupted) {
    out.reason = "stopped: interrupted after " + std::to_string(out.iterations) + " iterations";
  } else if (summary.termination_type == ceres::CONVERGENCE) {
    out.converged = true;
    out.reason = "converged: " + summary.message;
  } else if (summary.termination_type == ceres::NO_CONVERGENCE) {
    out.reason = "stopped: budget of " + std::to_string(options.max_iterations) +
                 " iterations spent (" + summary.message + ")";
  } else {
    out.reason = "stopped: " + summary.message;
  }
  return out;
}

}  // namespace caliper::calibration
