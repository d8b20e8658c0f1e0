#include "caliper/actuators/dc_motor.h"

#include <algorithm>
#include <boost/math/tools/toms748_solve.hpp>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "motor_checks.h"

namespace caliper::actuators {

using motor_detail::Check;
using motor_detail::Range;
using motor_detail::Text;

namespace {

// sharpness and offset of the efficiency switch in TENDONS.md [1/(A rad/s)], [-]
constexpr double kSwitchSharpness = 500;
constexpr double kSwitchOffset = 5;
// the SDIRK2 coefficient gamma = 1 - 1/sqrt(2) (L-stable, stiffly accurate)
const double kGamma = 1.0 - 1.0 / std::sqrt(2.0);
// absolute tolerance of the spool speed in each implicit stage of the fallback solver [rad/s]
constexpr double kSpeedTolerance = 1e-12;
// Newton's iteration stops when the speed after its step is within this times the speed scale
// |w| + 1 V / (k_e N) of the stage's solution (1e-12 rad/s as the bracketing solver's tolerance
// for the reference motor, 0.68 rad/s/V); steps below kRoundingStep of that are always taken
constexpr double kNewtonTolerance = 1.5e-12;
constexpr double kRoundingStep = 1e-3;
constexpr int kNewtonIterations = 50;
// A sub-step longer than kFineSubstep [s] is checked: where the difference between its result and
// the first-order one from its first stage's slope exceeds kSubstepTolerance [rad/s] (the current's
// difference counted as the speed it would give over one electrical time constant) it is redone
// as sub-steps of at most kFineSubstep. That happens just after a jump in the voltage or the load
// (the electrical transient, ~0.1 ms, and the start of the mechanical one); elsewhere the motion
// is smooth and long sub-steps are as accurate.
constexpr double kFineSubstep = 3.4e-4;
constexpr double kSubstepTolerance = 1e-3;
// beyond |1000 i w + 10| > 40 the switch is exactly 0 or 1 in rho (tanh is +-1 to the last bit
// from |500 i w + 5| > 19.1): no exp needed
constexpr double kSwitchSaturation = 40;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// (tanh(-500 i w - 5) + 1) / 2 written as 1 / (1 + exp(1000 i w + 10))
inline double SwitchBlend(double current_times_speed) {
  const double x = 2 * (kSwitchSharpness * current_times_speed + kSwitchOffset);
  if (x > kSwitchSaturation) return 0;
  if (x < -kSwitchSaturation) return 1;
  return 1 / (1 + std::exp(x));
}

// v in the shortest form (up to 17 digits, locale-free) that is >= v (up) or <= v (down), so
// that a bound read from a message and typed back is accepted
std::string BoundText(double v, bool up) {
  char text[32];
  for (int digits = 6; digits <= 17; ++digits) {
    const auto end = std::to_chars(text, text + sizeof text, v, std::chars_format::general, digits);
    double back = 0;
    std::from_chars(text, end.ptr, back);
    if (digits == 17 || (up ? back >= v : back <= v)) return std::string(text, end.ptr);
  }
  return std::to_string(v);
}

// A root of f near x0, for f dominated by x - x0 far from the root (slope about one).
// With first_step > 0 the search starts with a step no longer than that and doubles it: it
// brackets the nearest root unless another lies in the same doubled step (a heuristic).
template <class Function>
double FindRoot(const Function& f, double x0, double tolerance, double first_step = 0) {
  double f0 = f(x0);
  if (f0 == 0) return x0;
  double step = first_step > 0 ? std::copysign(std::min(first_step, std::abs(f0)), -f0) : -f0;
  double x1 = x0 + step;
  double f1 = f(x1);
  for (int expansion = 0; (f1 > 0) == (f0 > 0) && f1 != 0; ++expansion) {
    if (expansion > 200 || !std::isfinite(f1))
      throw std::runtime_error("dc motor: no solution for the implicit stage");
    x0 = x1;
    f0 = f1;
    step *= 2;
    x1 = x0 + step;
    f1 = f(x1);
  }
  if (f1 == 0) return x1;
  // TOMS 748 on the bracket, down to a width of `tolerance` (plus rounding): its middle is
  // within tolerance / 2 of a root
  if (x1 < x0) {
    std::swap(x0, x1);
    std::swap(f0, f1);
  }
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  const auto narrow_enough = [tolerance](double a, double b) {
    return b - a <= tolerance + 4 * kEps * std::max(std::abs(a), std::abs(b));
  };
  std::uintmax_t iterations = 200;
  const auto [a, b] =
      boost::math::tools::toms748_solve(f, x0, x1, f0, f1, narrow_enough, iterations);
  return 0.5 * (a + b);
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
  Check("coulomb_friction", "N m", coulomb_friction, Range::kNonNegative);
  Check("static_friction", "N m", static_friction, Range::kNonNegative);
  if (static_friction > 0 && static_friction < coulomb_friction)
    throw std::invalid_argument("parameter 'static_friction' (" + Text(static_friction) +
                                " N m) must be 0 or at least coulomb_friction (" +
                                Text(coulomb_friction) + " N m)");
  Check("stribeck_speed", "rad/s", stribeck_speed, Range::kPositive);
  Check("viscous_friction", "N m s/rad", viscous_friction, Range::kNonNegative);
  Check("friction_smoothing_speed", "rad/s", friction_smoothing_speed, Range::kPositive);
  Check("cogging_amplitude", "N m", cogging_amplitude, Range::kNonNegative);
  Check("cogging_count", "", cogging_count, Range::kPositive);
  if (cogging_count != std::floor(cogging_count) || cogging_count > 1e6)
    throw std::invalid_argument(
        "parameter 'cogging_count' must be a whole number of periods "
        "per rotor turn in [1, 1e6], got " +
        Text(cogging_count));
  Check("cogging_phase", "rad", cogging_phase, Range::kFinite);
  Check("thermal_resistance_winding_housing", "K/W", thermal_resistance_winding_housing,
        Range::kNonNegative);
  Check("thermal_resistance_housing_ambient", "K/W", thermal_resistance_housing_ambient,
        Range::kNonNegative);
  Check("thermal_time_constant_winding", "s", thermal_time_constant_winding, Range::kNonNegative);
  Check("thermal_time_constant_motor", "s", thermal_time_constant_motor, Range::kNonNegative);
  // on with R_ha, which a live edit sets last: the other three may be set before
  const bool any_thermal = thermal();
  if (any_thermal) {
    try {
      thermal_parameters().Validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(e.what()) +
                                  " (thermal_resistance_housing_ambient > 0 turns the thermal "
                                  "model on; it needs the other three thermal constants > 0)");
    }
  }
  Check("ambient_temperature", "degC", ambient_temperature, Range::kFinite);
  Check("reference_temperature", "degC", reference_temperature, Range::kFinite);
  Check("resistance_temperature_coefficient", "1/K", resistance_temperature_coefficient,
        Range::kFinite);
  Check("torque_constant_temperature_coefficient", "1/K", torque_constant_temperature_coefficient,
        Range::kFinite);
  if (ambient_temperature < -273.15)
    throw std::invalid_argument("parameter 'ambient_temperature' must be above -273.15 degC, got " +
                                Text(ambient_temperature));
  Check("max_winding_temperature", "degC", max_winding_temperature, Range::kNonNegative);
  if (any_thermal && max_winding_temperature > 0 && max_winding_temperature <= ambient_temperature)
    throw std::invalid_argument("parameter 'max_winding_temperature' (" +
                                Text(max_winding_temperature) +
                                " degC) must be above ambient_temperature (" +
                                Text(ambient_temperature) + " degC), or 0 for no protection");
  Check("derating_band", "K", derating_band, Range::kPositive);
}

double GearEfficiencyFactor(double efficiency, double current, double spool_speed) {
  const double blend = SwitchBlend(current * spool_speed);
  return efficiency + (1 / efficiency - efficiency) * blend;
}

double SpoolLoad::TorqueAlong(double spool_angle, double spool_speed, double h,
                              double angle_per_speed, double* slope, double* low,
                              double* high) const {
  const double dw = 1e-7 * std::max(1.0, std::abs(spool_speed));
  const double da = angle_per_speed * dw;
  *slope = (TorqueAt(spool_angle + da, spool_speed + dw, h) -
            TorqueAt(spool_angle - da, spool_speed - dw, h)) /
           (2 * dw);
  *low = *high = 0;
  return TorqueAt(spool_angle, spool_speed, h);
}

double ConstantSpoolLoad::TorqueAlong(double, double, double, double, double* slope, double* low,
                                      double* high) const {
  *slope = 0;
  *low = -std::numeric_limits<double>::infinity();
  *high = std::numeric_limits<double>::infinity();
  return torque_;
}

DcMotor::DcMotor(const DcMotorParameters& parameters) { set_parameters(parameters); }

void DcMotor::set_parameters(const DcMotorParameters& parameters) {
  parameters.Validate();
  const bool was_thermal = thermal_;
  parameters_ = parameters;
  effective_ = parameters;
  shaft_ = parameters.shaft_losses();
  friction_ = parameters.coulomb_friction > 0 || parameters.static_friction > 0 ||
              parameters.viscous_friction > 0;
  friction_constants_ = ShaftFriction(parameters);
  thermal_ = parameters.thermal();
  thermal_model_ = TwoNodeThermal{};  // configured at the next step
  constants_ = StageConstants{};      // recomputed at the next step
  continuous_ = 0;
  if (thermal_ && parameters.max_winding_temperature > 0)
    continuous_ = ContinuousCurrent(
        parameters.thermal_parameters(), parameters.max_winding_temperature,
        parameters.ambient_temperature, ResistanceAt(parameters.max_winding_temperature));
  if (!thermal_ || !was_thermal) {
    // the temperatures start at the ambient when the model is turned on; without it they
    // read the ambient
    state_.winding_temperature = state_.housing_temperature = parameters.ambient_temperature;
    winding_change_ = housing_change_ = 0;
    derating_ = 0;
  } else {
    UpdateEffective(applied_voltage_);  // what a hot motor reads stays hot
  }
}

void DcMotor::Reset() {
  state_ = DcMotorState{};
  state_.winding_temperature = state_.housing_temperature = parameters_.ambient_temperature;
  applied_voltage_ = 0;
  load_torque_ = 0;
  last_acceleration_ = 0;
  winding_change_ = housing_change_ = 0;
  derating_ = 0;
  effective_ = parameters_;
}

double DcMotor::Substeps(double dt, double max_substep) {
  return std::max(1.0, std::ceil(dt / max_substep - 1e-9));
}

void DcMotor::CheckSubsteps(double dt, double max_substep) {
  const double n = Substeps(dt, max_substep);
  if (n <= kMaxSubstepsPerStep) return;
  throw std::invalid_argument(
      "a time step of " + Text(dt) + " s with max_substep = " + Text(max_substep) + " s needs " +
      Text(n) + " sub-steps, more than the " + std::to_string(kMaxSubstepsPerStep) +
      " one step may take: max_substep must be at least " +
      BoundText(dt / kMaxSubstepsPerStep, true) + " s (or the time step at most " +
      BoundText(max_substep * kMaxSubstepsPerStep, false) + " s)");
}

void DcMotor::set_locked(bool locked) {
  locked_ = locked;
  if (locked_) state_.spool_speed = 0;
  last_acceleration_ = 0;
}

void DcMotor::UpdateConstants(double dt) {
  constants_ = ConstantsFor(dt, parameters_.max_substep);
  constants_resistance_ = effective_.resistance;
  constants_torque_constant_ = effective_.torque_constant;
  fine_stale_ = false;
  // the refined sub-steps, never more than kMaxSubstepsPerStep in one step
  const double fine = std::max(kFineSubstep, dt / kMaxSubstepsPerStep);
  refine_ = constants_.h > fine;
  if (refine_) fine_ = ConstantsFor(constants_.h, fine);
}

DcMotor::StageConstants DcMotor::ConstantsFor(double dt, double max_substep) const {
  const DcMotorParameters& p = effective_;
  StageConstants k;
  k.dt = dt;
  k.substeps = static_cast<int>(Substeps(dt, max_substep));  // checked by Step()
  k.h = dt / k.substeps;
  k.c = kGamma * k.h;
  k.inverse_c = 1 / k.c;
  k.second_base = (1 - kGamma) / kGamma;
  const double c_over_inertia = k.c / (p.gear_ratio * inertia());  // C = c / (N J)
  k.c_over_inductance = k.c / p.inductance;
  k.c_ratio = c_over_inertia / p.gear_ratio;
  k.spread = 1 / p.efficiency - p.efficiency;
  k.inverse_rho_driving = 1 / p.efficiency;
  k.inverse_rho_driven = 1 / (p.efficiency + k.spread);
  k.c_shaft = c_over_inertia;
  k.cogging_per_angle = p.cogging_count * p.gear_ratio;
  k.cogging_slope = p.cogging_amplitude * k.cogging_per_angle * k.c;
  k.cogging_curvature = 0.5 * k.cogging_slope * k.cogging_per_angle * k.c;
  Retune(&k);
  if (shaft_) {
    // the most tau_f can fall per rad/s of the motor: (tau_s - tau_c) max|d exp(-y^2)/dW|,
    // max |y exp(-y^2)| 2 / W_s = sqrt(2 / e) / W_s; cogging's A n per radian of the rotor,
    // N c radians per rad/s of w
    const double peak =
        p.static_friction > p.coulomb_friction
            ? (p.static_friction - p.coulomb_friction) * std::sqrt(2 / M_E) / p.stribeck_speed
            : 0.0;
    k.shaft_falling = c_over_inertia * (p.gear_ratio * peak + k.cogging_slope);
  }
  return k;
}

void DcMotor::Retune(StageConstants* constants) const {
  StageConstants& k = *constants;
  const DcMotorParameters& p = effective_;
  const double resistance = p.resistance + p.bridge_resistance;  // [ohm]
  const double emf = p.back_emf_constant * p.gear_ratio;         // [V s/rad] at the spool
  // the current at the end of a stage, L (i - i_a) / c = U - R i - emf w, solved for i
  const double inverse = 1 / (1 + k.c_over_inductance * resistance);
  k.current_base = inverse;
  k.current_drive = k.c_over_inductance * inverse;
  k.current_slope = -k.c_over_inductance * emf * inverse;
  k.c_torque = k.c_shaft * p.torque_constant;
  k.tolerance = kNewtonTolerance / emf;  // of the no-load speed at 1 V [rad/s]
  k.current_to_speed = p.torque_constant * p.inductance / (p.gear_ratio * inertia() * resistance);
}

double DcMotor::Exp(double x) const {
  // exp(x) = exp(x_last) exp(x - x_last), the latter by its Taylor polynomial of degree 4 while
  // |d| < 2^-10 (relative error below d^5/120 < 8e-18, under the rounding of a double): a motor
  // at rest, holding or creeping moves x by less than that between stages and reuses the last
  // exact value instead of calling exp()
  const double d = x - exp_argument_;
  if (std::abs(d) < 1.0 / (1 << 10))
    return exp_value_ * (1 + d * (1 + d * (0.5 + d * (1.0 / 6 + d * (1.0 / 24)))));
  exp_argument_ = x;
  exp_value_ = std::exp(x);
  return exp_value_;
}

DcMotor::Stage DcMotor::StageAt(const DcMotorState& a, double voltage, double w) const {
  const DcMotorParameters& p = effective_;
  const StageConstants& k = constants_;
  Stage s;
  s.spool_speed = w;
  s.spool_angle = a.spool_angle + k.c * w;
  s.current = k.current_base * a.current + k.current_drive * voltage + k.current_slope * w;
  s.voltage = voltage;
  if (p.current_limit > 0 && std::abs(s.current) > p.current_limit) {
    s.current = std::copysign(p.current_limit, s.current);
    s.voltage = p.inductance * (s.current - a.current) / k.c +
                (p.resistance + p.bridge_resistance) * s.current +
                p.back_emf_constant * p.gear_ratio * w;
  }
  return s;
}

// One implicit stage of SolveStage, w = a.w + c f(w), at the stage's base a, voltage and load.
// The residual R(w) = w - a.w - C k_t i + (C / N) tau / rho, C = c / (N J), with
// 1 / rho = (1 + e) / D, D = eta (1 + e) + 1/eta - eta, e = exp(x), x = 1000 i w + 10; with
// its slope, both times D^2 > 0 (1 where the switch is saturated) so that a Newton step costs
// one division; and what bounds its curvature.
// SolveStage's Newton loop calls its member functions at every iteration: they are inlined there
// (as the lambdas they were).
class DcMotor::StageEquation {
 public:
  struct Value {
    double residual, slope;          // R D^2, dR/dw D^2
    double scale;                    // D^2
    double torque, d_torque;         // tau [N m] and d(tau)/dw
    double affine_low, affine_high;  // changes of w over which tau stays on its tangent
    double d_inverse_x;              // d(1 / rho)/dx D^2 = (1/eta - eta) e
    double x_slope;                  // dx/dw
    double d_current;                // di/dw (0 while the current is limited)
    double shaft, d_shaft;           // friction and cogging [N m] and d/dw (0 without them)
    double friction, d_friction;     // friction alone [N m] and d/dw
    int regime;  // -1, +1: saturated (rho = eta + (1/eta - eta), eta exactly); 0; kUnloaded
  };
  static constexpr int kUnloaded = 2;  // no torque, no slope: the switch does not matter

  StageEquation(const DcMotor& motor, const DcMotorState& a, double voltage, double h_load,
                const SpoolLoad& load)
      : motor_(motor),
        k_(motor.constants_),
        current0_(k_.current_base * a.current + k_.current_drive * voltage),
        limit_(motor.effective_.current_limit),
        efficiency_(motor.effective_.efficiency),
        angle0_(a.spool_angle),
        speed0_(a.spool_speed),
        h_load_(h_load),
        load_(load) {}

  // the current at the end of the stage and the switch regime at a spool speed w
  [[gnu::always_inline]] inline int StateAt(double w, double* current, double* x) const {
    double i = current0_ + k_.current_slope * w;
    bool limited = limit_ > 0 && std::abs(i) > limit_;
    if (limited) i = std::copysign(limit_, i);
    *current = i;
    *x = 2 * (kSwitchSharpness * (i * w) + kSwitchOffset);
    const int regime = *x > kSwitchSaturation ? 1 : (*x < -kSwitchSaturation ? -1 : 0);
    return limited ? regime + 4 : regime;  // both in one number
  }

  [[gnu::always_inline]] inline int Evaluate(double w, Value* v) const {
    double current;
    double x;
    const int state = StateAt(w, &current, &x);
    v->regime = state > 2 ? state - 4 : state;
    v->d_current = state > 2 ? 0.0 : k_.current_slope;
    v->torque = load_.TorqueAlong(angle0_ + k_.c * w, w, h_load_, k_.c, &v->d_torque,
                                  &v->affine_low, &v->affine_high);
    v->x_slope = 2 * kSwitchSharpness * (v->d_current * w + current);
    double linear = w - speed0_ - k_.c_torque * current;
    double d_linear = 1 - k_.c_torque * v->d_current;
    v->shaft = v->d_shaft = v->friction = v->d_friction = 0;
    if (motor_.shaft_) {
      v->shaft =
          motor_.ShaftTorque(k_, w, angle0_ + k_.c * w, &v->d_shaft, &v->friction, &v->d_friction);
      linear += k_.c_shaft * v->shaft;
      d_linear += k_.c_shaft * v->d_shaft;
    }
    if (v->torque == 0 && v->d_torque == 0) {
      // unloaded (a slack line): rho does not matter
      v->regime = kUnloaded;
      v->scale = 1;
      v->d_inverse_x = 0;
      v->residual = linear;
      v->slope = d_linear;
    } else if (v->regime == 0) {
      const double e = motor_.Exp(x);
      const double d = efficiency_ * (1 + e) + k_.spread;
      const double rho_d = (1 + e) * d;  // D^2 / rho
      v->scale = d * d;
      v->d_inverse_x = k_.spread * e;
      v->residual = linear * v->scale + k_.c_ratio * v->torque * rho_d;
      v->slope = d_linear * v->scale +
                 k_.c_ratio * (v->d_torque * rho_d + v->torque * v->d_inverse_x * v->x_slope);
    } else {
      const double inverse_rho = v->regime > 0 ? k_.inverse_rho_driving : k_.inverse_rho_driven;
      v->scale = 1;
      v->d_inverse_x = 0;
      v->residual = linear + k_.c_ratio * v->torque * inverse_rho;
      v->slope = d_linear + k_.c_ratio * v->d_torque * inverse_rho;
    }
    return state;
  }

  // A bound of |R(w + step)| D^2 [rad/s] from the value at w, where R is linear in the step but
  // for the switch (bounded through |d^n(1/rho)/dx^n| <= |d(1/rho)/dx|, which grows at most as
  // e^|dx|; x is quadratic in w) and the load (evaluated at w + step and compared with its
  // tangent); infinite when the current limit or the switch's saturation changes over the step.
  [[gnu::always_inline]] inline double BoundAfter(const Value& v, int state, double w,
                                                  double step) const {
    const double next = w + step;
    double current;
    double x;
    const int next_state = StateAt(next, &current, &x);
    if (v.regime == kUnloaded ? (next_state > 2) != (state > 2) : next_state != state)
      return kInfinity;
    // the load off its tangent, seen through 1/rho <= 1/eta
    double bound = 0;
    if (motor_.shaft_) {
      // friction off its tangent where the step ends (unless it is affine between: viscous, or
      // the sign and the Stribeck peak saturated at both ends), cogging by its curvature's bound
      // A (n N c)^2 / 2 per (rad/s)^2
      const double n = motor_.parameters_.gear_ratio;
      if (motor_.friction_ && !motor_.friction_constants_.Affine(n * w, n * next)) {
        double d_friction;
        const double friction = motor_.friction_constants_.Torque(n * next, &d_friction);
        bound += k_.c_shaft * std::abs(friction - v.friction - n * d_friction * step) * v.scale;
      }
      bound += k_.c_shaft * k_.cogging_curvature * step * step * v.scale;
    }
    if (!(step >= v.affine_low && step <= v.affine_high)) {
      const double torque = load_.TorqueAt(angle0_ + k_.c * next, next, h_load_);
      bound += k_.c_ratio * k_.inverse_rho_driving *
               std::abs(torque - v.torque - v.d_torque * step) * v.scale;
    }
    if (v.regime == 0) {
      const double ds = std::abs(step);
      const double x_curvature = 4 * kSwitchSharpness * std::abs(v.d_current);
      const double x_slope = std::abs(v.x_slope) + x_curvature * ds;  // max |dx/dw|
      const double dx = x_slope * ds;                                 // max |x - x_w|
      if (dx > 0.5) return kInfinity;
      const double sigma = v.d_inverse_x * (1 + 2 * dx);  // >= |d^n(1/rho)/dx^n| D^2
      const double tau = std::abs(v.torque) + std::abs(v.d_torque) * ds;
      // max |d2(tau / rho)/dw2| D^2 with d2(tau)/dw2 = 0
      const double curvature =
          sigma * (tau * (x_slope * x_slope + x_curvature) + 2 * std::abs(v.d_torque) * x_slope);
      bound += 0.5 * k_.c_ratio * curvature * ds * ds;
    }
    return bound;
  }

  // Whether a solution w* is the first from the base speed a.w, as the bracketing search finds
  // it: R increases between them. The only term of dR/dw that can be negative is
  // (C/N) tau d(1/rho)/dw, d(1/rho)/dw = s_x x' with 0 <= s_x <= (1/eta - eta)/4 (dR/dw >= 1
  // without it): it cannot when the switch is saturated over the interval or tau x' >= 0 there,
  // and is too small when (C/N) max|tau| (1/eta - eta)/4 max|x'| < 1/2 (|tau| taken at the ends).
  // Otherwise the stage may have several solutions (a current against the load while the speed
  // crosses zero) and the bracketing search decides.
  [[gnu::always_inline]] inline bool FirstFromBase(const Value& v, double w_eval,
                                                   double step) const {
    const double w_star = w_eval + step;
    const int sign = motor_.load_sign_;
    // friction's Stribeck peak and cogging may lower dR/dw by up to shaft_falling, the switch's
    // part by what the tests below bound: together below 1, R increases
    const double room = 1 - k_.shaft_falling;  // what the switch may take
    if (room <= 0) return false;
    double tau = -1;  // max |tau| at the ends, once known
    auto max_torque = [&] {
      if (tau < 0) {
        const double back = speed0_ - w_eval;  // to the base speed
        const double torque0 = back >= v.affine_low && back <= v.affine_high
                                   ? v.torque + v.d_torque * back
                                   : load_.TorqueAt(angle0_ + k_.c * speed0_, speed0_, h_load_);
        tau = std::max(std::abs(v.torque) + std::abs(v.d_torque * step), std::abs(torque0));
      }
      return tau;
    };
    if (limit_ == 0) {
      // x' = 1000 (i0 + 2 s w) is affine: its values at the ends bound it
      const double x_slope0 = 2 * kSwitchSharpness * (current0_ + 2 * k_.current_slope * speed0_);
      const double x_slope1 = 2 * kSwitchSharpness * (current0_ + 2 * k_.current_slope * w_star);
      if (sign > 0 ? (x_slope0 >= 0 && x_slope1 >= 0)
                   : (sign < 0 && x_slope0 <= 0 && x_slope1 <= 0))
        return true;
      const double x_slope = std::max(std::abs(x_slope0), std::abs(x_slope1));
      if (k_.c_ratio * max_torque() * 0.25 * k_.spread * x_slope < 0.5 * room) return true;
    }
    const double lo = std::min(speed0_, w_star);
    const double hi = std::max(speed0_, w_star);
    double x_min = kInfinity;
    double x_max = -kInfinity;
    double x_slope_min = kInfinity;
    double x_slope_max = -kInfinity;
    auto x_slope_at = [&](double current, double d_current, double w) {
      const double x_slope = 2 * kSwitchSharpness * (current + d_current * w);
      x_slope_min = std::min(x_slope_min, x_slope);
      x_slope_max = std::max(x_slope_max, x_slope);
    };
    auto visit = [&](double w) {
      double current;
      double x;
      const int state = StateAt(w, &current, &x);
      x_min = std::min(x_min, x);
      x_max = std::max(x_max, x);
      x_slope_at(current, state > 2 ? 0.0 : k_.current_slope, w);
    };
    visit(lo);
    visit(hi);
    // x = 1000 i w + 10 is quadratic in w where the current is not limited: its vertex
    const double vertex = -current0_ / (2 * k_.current_slope);
    if (vertex > lo && vertex < hi) visit(vertex);
    // where the limit starts, both sides
    if (limit_ > 0) {
      for (const double bound : {limit_, -limit_}) {
        const double w = (bound - current0_) / k_.current_slope;
        if (!(w > lo && w < hi)) continue;
        const double x = 2 * (kSwitchSharpness * (bound * w) + kSwitchOffset);
        x_min = std::min(x_min, x);
        x_max = std::max(x_max, x);
        x_slope_at(bound, 0.0, w);
        x_slope_at(bound, k_.current_slope, w);
      }
    }
    if (x_min > kSwitchSaturation || x_max < -kSwitchSaturation) return true;
    if ((sign > 0 && x_slope_min >= 0) || (sign < 0 && x_slope_max <= 0)) return true;
    const double x_slope = std::max(std::abs(x_slope_min), std::abs(x_slope_max));
    return k_.c_ratio * max_torque() * 0.25 * k_.spread * x_slope < 0.5 * room;
  }

 private:
  const DcMotor& motor_;
  const StageConstants& k_;
  const double current0_;    // the current at the end of the stage at w = 0 [A]
  const double limit_;       // current_limit [A]
  const double efficiency_;  // [-]
  const double angle0_;      // the base's spool angle [rad]
  const double speed0_;      // the base's spool speed [rad/s]
  const double h_load_;      // the stage's end after the last sub-step [s]
  const SpoolLoad& load_;
};

double DcMotor::SolveStage(const DcMotorState& a, double voltage, double h_load, double w0,
                           const SpoolLoad& load) const {
  const StageConstants& k = constants_;
  const StageEquation stage(*this, a, voltage, h_load, load);
  // Safeguarded Newton: the residual increases with w, so each value narrows a bracket. It stops
  // when the bound of the residual after the step puts the speed within the tolerance of the
  // stage's solution, usually after the first step from the guess.
  double low = -kInfinity;
  double high = kInfinity;
  double w = w0;
  for (int iteration = 0; iteration < kNewtonIterations; ++iteration) {
    StageEquation::Value v;
    const int state = stage.Evaluate(w, &v);
    if (!std::isfinite(v.residual) || !(v.slope > 0) || !std::isfinite(v.slope)) break;
    const double step = v.residual == 0 ? 0.0 : -v.residual / v.slope;
    const double tolerance = k.tolerance + kNewtonTolerance * std::abs(w);  // [rad/s]
    if (std::abs(step) <= kRoundingStep * tolerance ||
        stage.BoundAfter(v, state, w, step) <= tolerance * v.slope) {
      if (!stage.FirstFromBase(v, w, step)) break;
      return w + step;
    }
    (v.residual < 0 ? low : high) = w;
    w += step;
    if (!(w > low && w < high)) {
      if (!std::isfinite(low) || !std::isfinite(high)) break;
      w = 0.5 * (low + high);  // bisection when Newton leaves the bracket
    }
  }
  return SolveStageBracketing(a, voltage, h_load, load);
}

double DcMotor::SolveStageBracketing(const DcMotorState& a, double voltage, double h_load,
                                     const SpoolLoad& load) const {
  const DcMotorParameters& p = effective_;
  const StageConstants& k = constants_;
  const double inertia = p.gear_ratio * this->inertia();  // N J [kg m^2]
  auto residual = [&](double w) {
    const Stage s = StageAt(a, voltage, w);
    const double torque = load.TorqueAt(s.spool_angle, w, h_load);
    const double rho = GearEfficiencyFactor(p.efficiency, s.current, w);
    double d_shaft;
    double friction;
    double d_friction;
    const double shaft =
        shaft_ ? ShaftTorque(k, w, s.spool_angle, &d_shaft, &friction, &d_friction) : 0.0;
    const double acceleration =
        (p.torque_constant * s.current - torque / (rho * p.gear_ratio) - shaft) / inertia;
    return w - a.spool_speed - k.c * acceleration;
  };
  // where friction falls with speed (a Stribeck peak) or cogging acts, a stage may have several
  // solutions close together (a stuck motor's creep next to a sliding one): the search starts
  // with steps of a fraction of the smoothing speed or of a cogging period, so that it finds
  // the first from the base unless two lie within one of its doubled steps
  double first_step = 0;
  if (p.static_friction > p.coulomb_friction)
    first_step = 0.01 * p.friction_smoothing_speed / p.gear_ratio;
  if (p.cogging_amplitude > 0) {
    const double period = 2 * M_PI / (k.cogging_per_angle * k.c);  // of w [rad/s]
    first_step = first_step > 0 ? std::min(first_step, 0.1 * period) : 0.1 * period;
  }
  return FindRoot(residual, a.spool_speed, kSpeedTolerance, first_step);
}

bool DcMotor::Substep(double voltage, SpoolLoad& load, bool last, bool check) {
  const double h = constants_.h;
  const double c = constants_.c;
  const DcMotorState y = state_;
  // first stage, Y1 = y + c f(Y1), its speed guessed from the slope at the end of the last
  // sub-step
  const double w1 =
      locked_ ? 0.0 : SolveStage(y, voltage, c, y.spool_speed + c * last_acceleration_, load);
  const Stage first = StageAt(y, voltage, w1);
  // second stage: y + (1 - gamma) h f(Y1) + c f(Y2) with f(Y1) = (Y1 - y) / c, its speed guessed
  // from y + h f(Y1)
  const double k = constants_.second_base;
  DcMotorState a = y;
  a.current += k * (first.current - y.current);
  a.spool_speed += k * (first.spool_speed - y.spool_speed);
  a.spool_angle += k * (first.spool_angle - y.spool_angle);
  const double slope1 = (w1 - y.spool_speed) * constants_.inverse_c;
  const double w2 = locked_ ? 0.0 : SolveStage(a, voltage, h, y.spool_speed + h * slope1, load);
  const Stage second = StageAt(a, voltage, w2);
  if (check) {
    // against the first-order result y + h f(Y1); nothing is changed yet when it is refused
    const double speed_error = w2 - (y.spool_speed + h * slope1);
    const double current_error =
        second.current - (y.current + h * (first.current - y.current) * constants_.inverse_c);
    if (std::abs(speed_error) > kSubstepTolerance ||
        std::abs(current_error) * constants_.current_to_speed > kSubstepTolerance)
      return false;
  }
  last_acceleration_ = (w2 - a.spool_speed) * constants_.inverse_c;
  if (thermal_) joule_ += 0.5 * h * (y.current * y.current + second.current * second.current);
  state_.current = second.current;
  state_.spool_speed = second.spool_speed;
  state_.spool_angle = second.spool_angle;
  applied_voltage_ = second.voltage;
  if (last) load_torque_ = load.TorqueAt(second.spool_angle, w2, h);
  load.Advance(state_.spool_angle, state_.spool_speed, h);
  return true;
}

void DcMotor::Step(double voltage, double dt, SpoolLoad& load) {
  if (!std::isfinite(voltage))
    throw std::invalid_argument("dc motor: voltage must be finite, got " + std::to_string(voltage));
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("dc motor: time step must be > 0 [s], got " + std::to_string(dt));
  if (dt != constants_.dt) {
    try {
      CheckSubsteps(dt, parameters_.max_substep);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("dc motor: ") + e.what());
    }
    UpdateConstants(dt);
  }
  if (thermal_) BeginThermalStep(voltage, dt);
  load_sign_ = load.TorqueSign();
  const int n = constants_.substeps;
  for (int i = 0; i < n; ++i) {
    const bool last = i + 1 == n;
    if (Substep(voltage, load, last, refine_)) continue;
    // redone in shorter sub-steps (the stages' constants swapped in for them)
    if (fine_stale_) {
      Retune(&fine_);
      fine_stale_ = false;
    }
    std::swap(constants_, fine_);
    const int m = constants_.substeps;
    for (int j = 0; j < m; ++j) Substep(voltage, load, last && j + 1 == m, false);
    std::swap(constants_, fine_);
  }
  if (thermal_) EndThermalStep(dt);
}

double DcMotor::ShaftTorque(const StageConstants& k, double w, double phi, double* d_torque,
                            double* friction, double* d_friction) const {
  const DcMotorParameters& p = parameters_;
  *friction = *d_friction = 0;
  if (friction_) {
    *friction = friction_constants_.Torque(p.gear_ratio * w, d_friction);
    *d_friction *= p.gear_ratio;
  }
  double torque = *friction;
  *d_torque = *d_friction;
  if (p.cogging_amplitude > 0) {
    double sine;
    double cosine;
    SinCos(k.cogging_per_angle * phi + p.cogging_phase, &sine, &cosine);
    torque += p.cogging_amplitude * sine;
    *d_torque += k.cogging_slope * cosine;
  }
  return torque;
}

void DcMotor::SinCos(double x, double* sine, double* cosine) const {
  // sin and cos of x_last + d by the angle sum, with d's own by their Taylor polynomials while
  // |d| < 2^-8 (errors below d^8/8! < 1.4e-24): a Newton iteration moves the cogging angle by
  // far less, and only each stage's first evaluation calls sin and cos
  const double d = x - sin_argument_;
  if (std::abs(d) < 1.0 / (1 << 8)) {
    const double d2 = d * d;
    const double cd = 1 - d2 * (0.5 - d2 * (1.0 / 24 - d2 * (1.0 / 720)));
    const double sd = d * (1 - d2 * (1.0 / 6 - d2 * (1.0 / 120 - d2 * (1.0 / 5040))));
    *sine = sin_value_ * cd + cos_value_ * sd;
    *cosine = cos_value_ * cd - sin_value_ * sd;
    return;
  }
  sin_argument_ = x;
  sin_value_ = std::sin(x);
  cos_value_ = std::cos(x);
  *sine = sin_value_;
  *cosine = cos_value_;
}

ShaftFriction::ShaftFriction(const DcMotorParameters& p)
    : viscous_(p.viscous_friction),
      coulomb_(p.coulomb_friction),
      peak_(std::max(0.0, p.static_friction - p.coulomb_friction)),
      inverse_smoothing_(1 / p.friction_smoothing_speed),
      inverse_stribeck_(1 / p.stribeck_speed),
      sign_speed_(19.1 * p.friction_smoothing_speed),
      peak_speed_(6 * p.stribeck_speed),
      dry_(p.coulomb_friction > 0 || p.static_friction > 0) {}

bool ShaftFriction::Affine(double speed0, double speed1) const {
  if (!dry_) return true;
  if (!((speed0 >= sign_speed_ && speed1 >= sign_speed_) ||
        (speed0 <= -sign_speed_ && speed1 <= -sign_speed_)))
    return false;
  return peak_ == 0 || (std::abs(speed0) >= peak_speed_ && std::abs(speed1) >= peak_speed_);
}

double ShaftFriction::Torque(double speed, double* slope) const {
  double torque = viscous_ * speed;
  *slope = viscous_;
  if (!dry_) return torque;
  // tanh(x) is +-1 to the last bit beyond |x| = 19.1, exp(-y^2) below 3e-16 beyond |y| = 6
  double sign = speed > 0 ? 1.0 : (speed < 0 ? -1.0 : 0.0);
  double d_sign = 0;
  if (std::abs(speed) < sign_speed_) {
    sign = std::tanh(speed * inverse_smoothing_);
    d_sign = (1 - sign * sign) * inverse_smoothing_;
  }
  double level = coulomb_;
  double d_level = 0;
  if (peak_ > 0 && std::abs(speed) < peak_speed_) {
    const double y = speed * inverse_stribeck_;
    const double e = std::exp(-y * y);
    level += peak_ * e;
    d_level = -2 * y * peak_ * e * inverse_stribeck_;
  }
  *slope += d_level * sign + level * d_sign;
  return torque + level * sign;
}

double DcMotor::friction_torque() const {
  double slope;
  return friction_ ? friction_constants_.Torque(motor_speed(), &slope) : 0.0;
}

double DcMotor::cogging_torque() const {
  const DcMotorParameters& p = parameters_;
  if (p.cogging_amplitude == 0) return 0;
  return p.cogging_amplitude *
         std::sin(p.cogging_count * p.gear_ratio * state_.spool_angle + p.cogging_phase);
}

double DcMotor::continuous_current() const { return continuous_; }

double DcMotor::ResistanceAt(double winding) const {
  const DcMotorParameters& p = parameters_;
  return p.resistance * std::max(0.05, 1 + p.resistance_temperature_coefficient *
                                               (winding - p.reference_temperature));
}

void DcMotor::UpdateEffective(double voltage) {
  const DcMotorParameters& p = parameters_;
  const double winding = state_.winding_temperature + 0.5 * winding_change_;
  const double housing = state_.housing_temperature + 0.5 * housing_change_;
  const double k_factor = std::max(
      0.05, 1 + p.torque_constant_temperature_coefficient * (housing - p.reference_temperature));
  effective_.resistance = ResistanceAt(winding);
  effective_.torque_constant = p.torque_constant * k_factor;
  effective_.back_emf_constant = p.back_emf_constant * k_factor;
  // the driver's protection, from the winding's temperature at the start of the step: its limit
  // moves from its own (without one, the most the voltage can drive now, back-EMF included)
  // to the continuous current, never above its own
  derating_ = 0;
  effective_.current_limit = p.current_limit;
  if (p.max_winding_temperature == 0) return;
  const double start = p.max_winding_temperature - p.derating_band;
  derating_ = std::clamp((state_.winding_temperature - start) / p.derating_band, 0.0, 1.0);
  if (derating_ == 0) return;
  const double top = p.current_limit > 0
                         ? p.current_limit
                         : (std::abs(voltage) + effective_.back_emf_constant * p.gear_ratio *
                                                    std::abs(state_.spool_speed)) /
                               (effective_.resistance + p.bridge_resistance);
  double limit = top + (continuous_ - top) * derating_;
  if (p.current_limit > 0) limit = std::min(limit, p.current_limit);
  effective_.current_limit = limit;  // > 0: a mean of top >= 0 and continuous_ > 0
}

void DcMotor::BeginThermalStep(double voltage, double dt) {
  if (thermal_model_.dt() != dt) thermal_model_.Configure(parameters_.thermal_parameters(), dt);
  UpdateEffective(voltage);
  // only what the temperatures change, and only when they changed it; the refined sub-steps'
  // when they are needed
  if (effective_.resistance != constants_resistance_ ||
      effective_.torque_constant != constants_torque_constant_) {
    Retune(&constants_);
    fine_stale_ = refine_;
    constants_resistance_ = effective_.resistance;
    constants_torque_constant_ = effective_.torque_constant;
  }
  joule_ = 0;
}

void DcMotor::EndThermalStep(double dt) {
  const double ambient = parameters_.ambient_temperature;
  double winding = state_.winding_temperature - ambient;
  double housing = state_.housing_temperature - ambient;
  // the Joule power in the winding (the bridge's resistance heats the driver, not the motor)
  thermal_model_.Step(effective_.resistance * joule_ / dt, &winding, &housing);
  winding_change_ = winding + ambient - state_.winding_temperature;
  housing_change_ = housing + ambient - state_.housing_temperature;
  state_.winding_temperature = winding + ambient;
  state_.housing_temperature = housing + ambient;
}

void DcMotor::Step(double voltage, double dt, double load_torque) {
  ConstantSpoolLoad load(load_torque);
  Step(voltage, dt, load);
}

}  // namespace caliper::actuators
