#include "caliper/actuators/dc_motor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace caliper::actuators {

namespace {

// sharpness and offset of the efficiency switch in TENDONS.md [1/(A rad/s)], [-]
constexpr double kSwitchSharpness = 500;
constexpr double kSwitchOffset = 5;
// the SDIRK2 coefficient gamma = 1 - 1/sqrt(2) (L-stable, stiffly accurate)
const double kGamma = 1.0 - 1.0 / std::sqrt(2.0);
// absolute tolerance of the spool speed in each implicit stage [rad/s]
constexpr double kSpeedTolerance = 1e-12;

enum class Range { kPositive, kNonNegative, kFraction };

void Check(const char* name, const char* unit, double value, Range range) {
  bool ok = std::isfinite(value);
  const char* expected = "finite";
  switch (range) {
    case Range::kPositive:
      ok = ok && value > 0;
      expected = "> 0";
      break;
    case Range::kNonNegative:
      ok = ok && value >= 0;
      expected = ">= 0";
      break;
    case Range::kFraction:
      ok = ok && value > 0 && value <= 1;
      expected = "in (0, 1]";
      break;
  }
  if (!ok) {
    std::ostringstream message;
    message << "parameter '" << name << "' must be " << expected << " [" << unit << "], got "
            << value;
    throw std::invalid_argument(message.str());
  }
}

// Brent's method on a bracket [a, b] with f(a), f(b) of opposite signs.
template <class Function>
double Brent(const Function& f, double a, double b, double fa, double fb, double tolerance) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  double c = b;
  double fc = fb;
  double d = b - a;
  double e = d;
  for (int iteration = 0; iteration < 200; ++iteration) {
    if ((fb > 0 && fc > 0) || (fb < 0 && fc < 0)) {
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::abs(fc) < std::abs(fb)) {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol = 2 * kEps * std::abs(b) + 0.5 * tolerance;
    const double m = 0.5 * (c - b);
    if (std::abs(m) <= tol || fb == 0) return b;
    if (std::abs(e) >= tol && std::abs(fa) > std::abs(fb)) {
      const double s = fb / fa;
      double p;
      double q;
      if (a == c) {
        p = 2 * m * s;
        q = 1 - s;
      } else {
        const double qa = fa / fc;
        const double r = fb / fc;
        p = s * (2 * m * qa * (qa - r) - (b - a) * (r - 1));
        q = (qa - 1) * (r - 1) * (s - 1);
      }
      if (p > 0) q = -q;
      p = std::abs(p);
      if (2 * p < std::min(3 * m * q - std::abs(tol * q), std::abs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = m;
        e = m;
      }
    } else {
      d = m;
      e = m;
    }
    a = b;
    fa = fb;
    b += std::abs(d) > tol ? d : (m > 0 ? tol : -tol);
    fb = f(b);
  }
  return b;
}

// A root of f near x0, for f dominated by x - x0 far from the root (slope about one).
template <class Function>
double FindRoot(const Function& f, double x0, double tolerance) {
  double f0 = f(x0);
  if (f0 == 0) return x0;
  double step = -f0;
  double x1 = x0 + step;
  double f1 = f(x1);
  for (int expansion = 0; (f1 > 0) == (f0 > 0) && f1 != 0; ++expansion) {
    if (expansion > 100 || !std::isfinite(f1))
      throw std::runtime_error("dc motor: no solution for the implicit stage");
    x0 = x1;
    f0 = f1;
    step *= 2;
    x1 = x0 + step;
    f1 = f(x1);
  }
  if (f1 == 0) return x1;
  return Brent(f, x0, x1, f0, f1, tolerance);
}

}  // namespace

void DcMotorParameters::Validate() const {
  Check("resistance", "ohm", resistance, Range::kPositive);
  Check("inductance", "H", inductance, Range::kPositive);
  Check("torque_constant", "N m/A", torque_constant, Range::kPositive);
  Check("back_emf_constant", "V s/rad", back_emf_constant, Range::kPositive);
  Check("rotor_inertia", "kg m^2", rotor_inertia, Range::kPositive);
  Check("gear_inertia", "kg m^2", gear_inertia, Range::kNonNegative);
  Check("gear_ratio", "", gear_ratio, Range::kPositive);
  Check("efficiency", "", efficiency, Range::kFraction);
  Check("bridge_resistance", "ohm", bridge_resistance, Range::kNonNegative);
  Check("current_limit", "A", current_limit, Range::kNonNegative);
  Check("spool_radius", "m", spool_radius, Range::kPositive);
  Check("max_substep", "s", max_substep, Range::kPositive);
}

double GearEfficiencyFactor(double efficiency, double current, double spool_speed) {
  const double blend =
      (std::tanh(-kSwitchSharpness * current * spool_speed - kSwitchOffset) + 1) / 2;
  return efficiency + (1 / efficiency - efficiency) * blend;
}

DcMotor::DcMotor(const DcMotorParameters& parameters) { set_parameters(parameters); }

void DcMotor::set_parameters(const DcMotorParameters& parameters) {
  parameters.Validate();
  parameters_ = parameters;
}

void DcMotor::Reset() {
  state_ = DcMotorState{};
  applied_voltage_ = 0;
  load_torque_ = 0;
}

void DcMotor::set_locked(bool locked) {
  locked_ = locked;
  if (locked_) state_.spool_speed = 0;
}

DcMotor::Stage DcMotor::SolveStage(const DcMotorState& a, double c, double voltage, double h,
                                   const SpoolLoad& load) const {
  const DcMotorParameters& p = parameters_;
  const double resistance = p.resistance + p.bridge_resistance;  // [ohm]
  const double emf = p.back_emf_constant * p.gear_ratio;         // [V s/rad] at the spool
  const double inertia = p.gear_ratio * this->inertia();         // N J [kg m^2]

  // the current at the end of the stage for a spool speed w: linear, then limited
  auto solve = [&](double w, Stage* s) {
    s->spool_speed = w;
    s->spool_angle = a.spool_angle + c * w;
    s->current =
        (a.current + c * (voltage - emf * w) / p.inductance) / (1 + c * resistance / p.inductance);
    s->voltage = voltage;
    if (p.current_limit > 0 && std::abs(s->current) > p.current_limit) {
      s->current = std::copysign(p.current_limit, s->current);
      s->voltage = p.inductance * (s->current - a.current) / c + resistance * s->current + emf * w;
    }
    s->torque = load.TorqueAt(s->spool_angle, w, h);
  };
  auto residual = [&](double w) {
    Stage s;
    solve(w, &s);
    const double rho = GearEfficiencyFactor(p.efficiency, s.current, w);
    const double acceleration =
        (p.torque_constant * s.current - s.torque / (rho * p.gear_ratio)) / inertia;
    return w - a.spool_speed - c * acceleration;
  };

  Stage stage;
  const double w = locked_ ? 0.0 : FindRoot(residual, a.spool_speed, kSpeedTolerance);
  solve(w, &stage);
  return stage;
}

void DcMotor::Substep(double voltage, double h, SpoolLoad& load) {
  const double c = kGamma * h;
  const Stage first = SolveStage(state_, c, voltage, c, load);
  // second stage: y + (1 - gamma) h f(Y1) with f(Y1) = (Y1 - y) / (gamma h)
  const double k = (1 - kGamma) / kGamma;
  DcMotorState a = state_;
  a.current += k * (first.current - state_.current);
  a.spool_speed += k * (first.spool_speed - state_.spool_speed);
  a.spool_angle += k * (first.spool_angle - state_.spool_angle);
  const Stage second = SolveStage(a, c, voltage, h, load);
  state_.current = second.current;
  state_.spool_speed = second.spool_speed;
  state_.spool_angle = second.spool_angle;
  applied_voltage_ = second.voltage;
  load_torque_ = second.torque;
  load.Advance(state_.spool_angle, state_.spool_speed, h);
}

void DcMotor::Step(double voltage, double dt, SpoolLoad& load) {
  if (!std::isfinite(voltage))
    throw std::invalid_argument("dc motor: voltage must be finite, got " + std::to_string(voltage));
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("dc motor: time step must be > 0 [s], got " + std::to_string(dt));
  const int n = std::max(1, static_cast<int>(std::ceil(dt / parameters_.max_substep - 1e-9)));
  const double h = dt / n;
  for (int i = 0; i < n; ++i) Substep(voltage, h, load);
}

void DcMotor::Step(double voltage, double dt, double load_torque) {
  ConstantSpoolLoad load(load_torque);
  Step(voltage, dt, load);
}

}  // namespace caliper::actuators
