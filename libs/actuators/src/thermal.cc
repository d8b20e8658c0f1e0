#include "caliper/actuators/thermal.h"

#include <cmath>
#include <stdexcept>

#include "motor_checks.h"

namespace caliper::actuators {

namespace {

// (exp(z) - 1) / z, 1 at z = 0
double Phi1(double z) { return z == 0 ? 1.0 : std::expm1(z) / z; }

}  // namespace

void ThermalParameters::Validate() const {
  using motor_detail::Check;
  using motor_detail::Range;
  Check("thermal_resistance_winding_housing", "K/W", resistance_winding_housing, Range::kPositive);
  Check("thermal_resistance_housing_ambient", "K/W", resistance_housing_ambient, Range::kPositive);
  Check("thermal_time_constant_winding", "s", time_constant_winding, Range::kPositive);
  Check("thermal_time_constant_motor", "s", time_constant_motor, Range::kPositive);
}

void TwoNodeThermal::Configure(const ThermalParameters& p, double dt) {
  p.Validate();
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("thermal model: time step must be > 0 [s], got " +
                                motor_detail::Text(dt));
  const double cw = p.winding_capacity();
  const double ch = p.housing_capacity();
  const double gwh = 1 / p.resistance_winding_housing;  // [W/K]
  const double gha = 1 / p.resistance_housing_ambient;  // [W/K]
  // A = [[a, b], [c, d]]
  const double a = -gwh / cw;
  const double b = gwh / cw;
  const double c = gwh / ch;
  const double d = -(gwh + gha) / ch;
  // eigenvalues (a + d)/2 -+ sqrt(((a - d)/2)^2 + b c), b c > 0: real and distinct; the one
  // nearer zero from the product (det / fast) to keep its digits
  const double half_trace = 0.5 * (a + d);
  const double root = std::sqrt(0.25 * (a - d) * (a - d) + b * c);
  fast_ = half_trace - root;
  slow_ = (a * d - b * c) / fast_;
  // f(A) = f(l1) (A - l2 I) / (l1 - l2) + f(l2) (A - l1 I) / (l2 - l1)
  const double l1 = fast_;
  const double l2 = slow_;
  const double e1 = std::exp(l1 * dt);
  const double e2 = std::exp(l2 * dt);
  const double g1 = dt * Phi1(l1 * dt);  // (exp(l dt) - 1) / l
  const double g2 = dt * Phi1(l2 * dt);
  const double gap = l1 - l2;
  auto sylvester = [&](double f1, double f2, double* out) {
    const double s = (f1 - f2) / gap;            // coefficient of A
    const double t = (f2 * l1 - f1 * l2) / gap;  // of I
    out[0] = s * a + t;
    out[1] = s * b;
    out[2] = s * c;
    out[3] = s * d + t;
  };
  sylvester(e1, e2, phi_);
  double g[4];
  sylvester(g1, g2, g);
  // Gamma = A^-1 (Phi - I) b with b = (1 / C_w, 0)
  gamma_[0] = g[0] / cw;
  gamma_[1] = g[2] / cw;
  dt_ = dt;
}

double ContinuousCurrent(const ThermalParameters& p, double max_winding, double ambient,
                         double hot_resistance) {
  const double rise = max_winding - ambient;
  if (!(rise > 0) || !(hot_resistance > 0)) return 0;
  return std::sqrt(
      rise / ((p.resistance_winding_housing + p.resistance_housing_ambient) * hot_resistance));
}

}  // namespace caliper::actuators
