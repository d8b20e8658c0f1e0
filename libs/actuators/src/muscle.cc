// The kind hill_muscle: the Hill muscle (activation, fibre and tendon states, the stage solvers of
// the elastic tendon) on the curves of muscle_curves.cc and millard.cc, its parameters from
// muscle_parameters.cc.

#include "caliper/actuators/muscle.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "builtin_kinds.h"
#include "caliper/actuators/actuator.h"
#include "command_delay.h"
#include "muscle_curves.h"
#include "muscle_parameters.h"
#include "muscle_validation.h"

namespace caliper::actuators {

namespace {

constexpr double kMaxSubstep = 1e-3;  // [s]

using muscle_detail::AllParameters;
using muscle_detail::AppliesTo;
using muscle_detail::Clamp;
using muscle_detail::Curves;
using muscle_detail::CurvesName;
using muscle_detail::kMinVal;
using muscle_detail::kPi;
using muscle_detail::Num;
using muscle_detail::ParameterTable;
using muscle_detail::Require;
using muscle_detail::ThelenEccentricFactor;
using muscle_detail::ThelenSpeedLimit;

// The activation a(h) of da/dt = (u - a) / tau with tau = tau_act (0.5 + 1.5 a) while u > a and
// tau_deact / (0.5 + 1.5 a) while u < a (the law of ActivationRate for a, u in [0, 1]; a never
// crosses u), solved exactly, P = 0.5 + 1.5 u:
//   rising, v = u - a:  P ln(v / v0) - 1.5 (v - v0) = -h / tau_act, solved for ln v by Halley's
//                       method from the tangent at v0 (left of the root of a concave, increasing
//                       function);
//   falling, w = a - u: w / (P + 1.5 w) = w0 / (P + 1.5 w0) exp(-P h / tau_deact).
double ExactActivation(double u, double a, double h, double tau_act, double tau_deact) {
  const double p = 0.5 + 1.5 * u;
  if (u > a) {
    const double v0 = u - a;
    const double y0 = std::log(v0);
    const double rhs = h / tau_act;
    double y = y0 - rhs / (0.5 + 1.5 * a);
    for (int i = 0; i < 20; ++i) {
      const double v = std::exp(y);
      const double g = p * (y - y0) - 1.5 * (v - v0) + rhs;
      const double slope = p - 1.5 * v;  // >= 0.5: v <= v0 <= u, p = 0.5 + 1.5 u
      const double curvature = -1.5 * v;
      const double step = -2 * g * slope / (2 * slope * slope - g * curvature);
      // converging cubically with a constant below 3 (|g'''| = |g''| <= 1.5, g' >= 0.5): after a
      // step below 1e-6 the error in y (relative in v) is below 3e-18
      if (std::abs(step) < 1e-6) return u - v * (1 + step * (1 + 0.5 * step));  // v e^step
      y += step;
    }
    return u - std::exp(y);
  }
  if (u < a) {
    const double w0 = a - u;
    const double q = w0 / (p + 1.5 * w0) * std::exp(-p * h / tau_deact);
    return u + q * p / (1 - 1.5 * q);
  }
  return a;
}

// root of f on [lo, hi] with f(lo) <= 0 <= f(hi); f returns (value, derivative); Newton steps,
// bisection when a step leaves the bracket or does not halve the error
template <class F>
double SafeNewton(const F& f, double lo, double hi, double x, double tol) {
  x = Clamp(x, lo, hi);
  double dx_old = hi - lo;
  double dx = dx_old;
  auto [fx, dfx] = f(x);
  for (int i = 0; i < 200; ++i) {
    if (fx == 0) return x;
    if (fx < 0)
      lo = x;
    else
      hi = x;
    const double newton = x - fx / dfx;
    if (dfx > 0 && newton > lo && newton < hi && std::abs(2 * fx) <= std::abs(dx_old * dfx)) {
      dx_old = dx;
      dx = x - newton;
      x = newton;
    } else {
      dx_old = dx;
      dx = 0.5 * (hi - lo);
      x = lo + dx;
    }
    if (std::abs(dx) < tol || hi - lo < tol) return x;
    std::tie(fx, dfx) = f(x);
  }
  return x;
}

struct Outputs {
  double fiber_length = 0;          // [m]
  double fiber_velocity = 0;        // [m/s]
  double norm_fiber_length = 0;     // [-]
  double norm_fiber_velocity = 0;   // [-]
  double pennation_cos = 1;         // cos(pennation) [-]; < 0: pi/2 (no fibre along the path)
  double tendon_length = 0;         // [m]
  double tendon_strain = 0;         // [-]
  double active_force_length = 0;   // [-]
  double force_velocity = 1;        // [-]
  double passive_force_length = 0;  // [-]
  double active_fiber_force = 0;    // [N]
  double passive_force = 0;         // [N]
  double tension = 0;               // [N]
};

class HillMuscle : public TendonActuator {
 public:
  HillMuscle(std::string name, Curves curves, bool elastic, const AllParameters& p)
      : name_(std::move(name)), curves_(curves), elastic_(elastic), p_(p) {
    activation_ = InitialActivation();
    fiber_length_ = curves_ == Curves::kMillard ? p_.millard.optimal_fiber_length
                                                : p_.thelen.optimal_fiber_length;
    UpdateDerived();
  }

  void Reset(double path_length) override {
    CheckFinite("path length", path_length);
    activation_ = InitialActivation();
    delay_.Reset(excitation_);
    if (elastic_)
      fiber_length_ = millard_ ? MillardEquilibrium(path_length, activation_)
                               : EquilibriumFiberLength(path_length, activation_);
    Evaluate(path_length, 0);
  }

  double Step(double path_length, double path_speed, double dt, double end_speed) override {
    CheckFinite("path length", path_length);
    CheckFinite("path speed", path_speed);
    CheckFinite("path speed at the end", end_speed);
    if (!(dt > 0) || !std::isfinite(dt))
      throw std::invalid_argument(Prefix() + "time step " + Num(dt) + " s must be > 0");
    try {
      delay_.Take(dt);  // the excitation this step follows: delayed_excitation()
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(Prefix() + e.what());
    }
    if (mujoco_integrator_) {
      // MuJoCo's order: the force of the current state, then act += dt * act_dot
      Evaluate(path_length, path_speed);
      const bool thelen = curves_ == Curves::kThelen;
      const double rate = ActivationRate(
          delayed_excitation(), activation_,
          thelen ? p_.thelen.activation_time_constant : p_.mujoco.tau_act,
          thelen ? p_.thelen.deactivation_time_constant : p_.mujoco.tau_deact, MinimumActivation());
      activation_ = Clamp(activation_ + dt * rate, MinimumActivation(), 1);
      return out_.tension;
    }
    if (millard_ && elastic_) return StepMillardElastic(path_length, path_speed, dt);
    // fibre sub-steps of at most 1 ms (activation takes finer ones inside)
    const int n = elastic_ ? FiberSubsteps(dt) : 1;
    const double h = dt / n;
    double velocity = out_.fiber_velocity;  // predicts the fibre's stage roots
    for (int i = 0; i < n; ++i) {
      const double a0 = activation_;
      activation_ = IntegrateActivation(a0, h);
      if (elastic_) {
        const double l0 = path_length + path_speed * i * h;
        fiber_length_ =
            FiberStep(fiber_length_, l0, l0 + path_speed * h, a0, activation_, h, &velocity);
      }
    }
    // a rigid tendon's force-velocity reads the path's speed at the end, where the tension acts
    Evaluate(path_length + path_speed * dt, end_speed);
    return out_.tension;
  }

  double tension() const override { return out_.tension; }

  // the activation, the fibre length and the outputs Get() reports (the solvers start afresh
  // from these in every step), then the excitations in flight
  std::size_t StateSize() const override { return 2 + kOutputValues + delay_.StateSize(); }
  bool Restorable(const double* in, std::size_t n) const override {
    const std::size_t fixed = 2 + kOutputValues;
    return n > fixed && CommandDelay::Readable(in + fixed, n - fixed);
  }
  void SaveState(double* out) const override {
    SaveOwnState(out);
    delay_.SaveState(out + 2 + kOutputValues);
  }
  void SaveStepState(double* out) const override {
    SaveOwnState(out);
    delay_.SaveStepState(out + 2 + kOutputValues);
  }
  void RestoreState(const double* in) override {
    RestoreOwnState(in);
    delay_.RestoreState(in + 2 + kOutputValues);
  }
  void RestoreStepState(const double* in) override {
    RestoreOwnState(in);
    delay_.RestoreStepState(in + 2 + kOutputValues);
  }

  void SetTimeStep(double dt) override {
    if (!(dt > 0) || !std::isfinite(dt))
      throw std::invalid_argument(Prefix() + "time step " + Num(dt) + " s must be > 0");
    if (elastic_) FiberSubsteps(dt);  // throws when there would be too many
    try {
      delay_.SetTimeStep(dt);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(Prefix() + e.what());
    }
  }

  void SetCommand(double value) override {
    CheckFinite("excitation", value);
    excitation_ = Clamp(value, 0, 1);
    delay_.Issue(excitation_);
  }
  double command() const override { return excitation_; }
  std::string command_unit() const override { return ""; }

  std::vector<Quantity> Quantities() const override {
    std::vector<Quantity> q;
    for (const auto& e : ParameterTable())
      if (AppliesTo(e.applies, curves_)) q.push_back({e.name, e.unit, true, true});
    if (curves_ == Curves::kMujoco) {
      q.push_back({"max_isometric_force", "N", false, true});
      q.push_back({"optimal_fiber_length", "m", false, true});
    }
    q.push_back({"command_delay", "s", true, true});
    q.push_back({"excitation", "", true, false});
    q.push_back({"delayed_command", "", false, false});
    q.push_back({"activation", "", true, false});
    q.push_back({"fiber_length", "m", elastic_, false});
    for (const auto& [name, unit] : OutputNames()) q.push_back({name, unit, false, false});
    if (curves_ != Curves::kMujoco) {
      q.push_back({"pennation", "rad", false, false});
      q.push_back({"tendon_length", "m", false, false});
      q.push_back({"tendon_strain", "", false, false});
    }
    return q;
  }

  // a reader of state `name`, or none when it is not one of this muscle's states
  std::function<double()> StateReader(const std::string& name) const {
    if (name == "excitation") return [this] { return excitation_; };
    if (name == "delayed_command") return [this] { return delay_.delayed(); };
    if (name == "activation") return [this] { return activation_; };
    if (name == "fiber_length")
      return [this] { return elastic_ ? fiber_length_ : out_.fiber_length; };
    if (name == "fiber_velocity") return [this] { return out_.fiber_velocity; };
    if (name == "normalized_fiber_length") return [this] { return out_.norm_fiber_length; };
    if (name == "normalized_fiber_velocity") return [this] { return out_.norm_fiber_velocity; };
    if (name == "active_force_length") return [this] { return out_.active_force_length; };
    if (name == "force_velocity") return [this] { return out_.force_velocity; };
    if (name == "passive_force_length") return [this] { return out_.passive_force_length; };
    if (name == "active_fiber_force") return [this] { return out_.active_fiber_force; };
    if (name == "passive_force") return [this] { return out_.passive_force; };
    if (name == "tension") return [this] { return out_.tension; };
    if (curves_ != Curves::kMujoco) {
      if (name == "pennation")
        return [this] { return out_.pennation_cos < 0 ? kPi / 2 : std::acos(out_.pennation_cos); };
      if (name == "tendon_length") return [this] { return out_.tendon_length; };
      if (name == "tendon_strain") return [this] { return out_.tendon_strain; };
    }
    return nullptr;
  }

  double Get(const std::string& name) const override {
    for (const auto& e : ParameterTable())
      if (e.name == name && AppliesTo(e.applies, curves_)) {
        AllParameters copy = p_;
        return e.ref(copy);
      }
    if (curves_ == Curves::kMujoco && name == "max_isometric_force") return MujocoF0();
    if (curves_ == Curves::kMujoco && name == "optimal_fiber_length") return MujocoL0();
    if (name == "command_delay") return delay_.delay();
    if (const auto read = StateReader(name)) return read();
    throw std::out_of_range(Prefix() + "no quantity '" + name + "'");
  }

  std::function<double()> Reader(const std::string& name) const override {
    if (auto read = StateReader(name)) return read;
    return TendonActuator::Reader(name);  // a parameter: read rarely
  }

  void Set(const std::string& name, double value) override {
    for (const auto& e : ParameterTable())
      if (e.name == name && AppliesTo(e.applies, curves_)) {
        AllParameters candidate = p_;
        e.ref(candidate) = value;
        try {
          ValidateAll(candidate, curves_, elastic_);
        } catch (const std::invalid_argument& error) {
          throw std::invalid_argument(Prefix() + error.what());
        }
        p_ = candidate;
        UpdateDerived();
        activation_ = Clamp(activation_, MinimumActivation(), 1);
        return;
      }
    if (name == "excitation") {
      SetCommand(value);
      return;
    }
    if (name == "command_delay") {
      try {
        delay_.SetDelay(value);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(Prefix() + e.what());
      }
      return;
    }
    if (name == "activation") {
      if (!(value >= MinimumActivation() && value <= 1))
        throw std::invalid_argument(Prefix() + "activation " + Num(value) + " must be in [" +
                                    Num(MinimumActivation()) + ", 1]");
      activation_ = value;
      return;
    }
    if (name == "fiber_length" && elastic_) {
      if (!(value >= MinimumFiberLength()) || !std::isfinite(value))
        throw std::invalid_argument(Prefix() + "fiber_length " + Num(value) +
                                    " m must be >= the shortest fibre " +
                                    Num(MinimumFiberLength()) + " m");
      fiber_length_ = value;
      return;
    }
    (void)Get(name);  // throws std::out_of_range for an unknown name
    throw std::invalid_argument(Prefix() + "'" + name + "' is read-only");
  }

  static void ValidateAll(const AllParameters& p, Curves curves, bool elastic) {
    Require(p.default_activation >= 0 && p.default_activation <= 1, "default_activation",
            p.default_activation, "must be in [0, 1]");
    if (curves == Curves::kThelen)
      Validate(p.thelen, elastic);
    else if (curves == Curves::kMillard)
      Validate(p.millard, elastic);
    else
      Validate(p.mujoco);
  }

 private:
  void SaveOwnState(double* out) const {
    out[0] = activation_;
    out[1] = fiber_length_;
    std::memcpy(out + 2, &out_, sizeof out_);
  }
  void RestoreOwnState(const double* in) {
    activation_ = in[0];
    fiber_length_ = in[1];
    std::memcpy(static_cast<void*>(&out_), in + 2, sizeof out_);
  }

  static const std::vector<std::pair<const char*, const char*>>& OutputNames() {
    static const std::vector<std::pair<const char*, const char*>> names = {
        {"fiber_velocity", "m/s"},
        {"normalized_fiber_length", ""},
        {"normalized_fiber_velocity", ""},
        {"active_force_length", ""},
        {"force_velocity", ""},
        {"passive_force_length", ""},
        {"active_fiber_force", "N"},
        {"passive_force", "N"},
        {"tension", "N"}};
    return names;
  }

  // the excitation the activation follows in this step: the command, `command_delay` late
  double delayed_excitation() const { return delay_.delayed(); }

  std::string Prefix() const {
    return "hill_muscle '" + name_ + "' (curves=" + CurvesName(curves_) + "): ";
  }

  void CheckFinite(const char* what, double v) const {
    if (!std::isfinite(v))
      throw std::invalid_argument(Prefix() + what + " is not finite (" + Num(v) + ")");
  }

  double MinimumActivation() const {
    if (curves_ == Curves::kMillard) return p_.millard.minimum_activation;
    return curves_ == Curves::kThelen ? p_.thelen.minimum_activation : 0.0;
  }
  double InitialActivation() const { return Clamp(p_.default_activation, MinimumActivation(), 1); }

  double MujocoF0() const {
    return MujocoForceScale(p_.mujoco.force, p_.mujoco.scale, p_.mujoco.acc0);
  }
  double MujocoL0() const {
    return MujocoOptimalLength(p_.mujoco.lengthrange_lo, p_.mujoco.lengthrange_hi, p_.mujoco.range0,
                               p_.mujoco.range1);
  }

  // The activation after h [s] with the excitation held: the exact solution of
  // da/dt = (u - a) / tau(a) (ActivationRate, MujocoActivationRate), clamped to [minimum, 1].
  double IntegrateActivation(double a, double h) const {
    const bool thelen = curves_ == Curves::kThelen;
    const double minimum = MinimumActivation();
    const double u = Clamp(delayed_excitation(), minimum, 1);
    a = Clamp(a, minimum, 1);
    double tau_act = thelen ? p_.thelen.activation_time_constant : p_.mujoco.tau_act;
    double tau_deact = thelen ? p_.thelen.deactivation_time_constant : p_.mujoco.tau_deact;
    if (curves_ == Curves::kMillard) {
      tau_act = p_.millard.activation_time_constant;
      tau_deact = p_.millard.deactivation_time_constant;
    }
    return Clamp(ExactActivation(u, a, h, tau_act, tau_deact), minimum, 1);
  }

  // the fibre sub-steps of a step of dt [s] (elastic tendon); throws std::invalid_argument when
  // there would be more than one step may take
  int FiberSubsteps(double dt) const {
    const double n = std::max(1.0, std::ceil(dt / kMaxSubstep - 1e-9));
    if (n > kMaxSubstepsPerStep)
      throw std::invalid_argument(Prefix() + "a time step of " + Num(dt) + " s needs " + Num(n) +
                                  " fibre sub-steps of " + Num(kMaxSubstep) +
                                  " s, more than the " + std::to_string(kMaxSubstepsPerStep) +
                                  " one step may take: the time step must be at most " +
                                  Num(kMaxSubstep * kMaxSubstepsPerStep) + " s");
    return static_cast<int>(n);
  }

  // --- Thelen with an elastic tendon: fibre length state

  // what the parameters give, once per change: the fibres' height, the shortest fibre, the
  // passive curve's denominator
  void UpdateDerived() {
    if (curves_ == Curves::kMillard) millard_ = std::make_unique<MillardFiberModel>(p_.millard);
    const ThelenMuscleParameters& t = p_.thelen;
    height_ = t.optimal_fiber_length * std::sin(t.pennation_angle);
    minimum_fiber_length_ =
        std::max(height_ / std::sin(t.maximum_pennation_angle), 0.01 * t.optimal_fiber_length);
    passive_denominator_ = std::exp(t.curves.kshape_passive) - 1;
    UpdateThelenElasticConstants();
  }

  // the constants of the elastic-tendon curves, so that a fibre evaluation in the step's Newton
  // solves costs one exp() per curve and no divisions by parameters
  void UpdateThelenElasticConstants() {
    const ThelenMuscleParameters& t = p_.thelen;
    const ThelenCurveParameters& c = t.curves;
    ElasticConstants& k = elastic_constants_;
    k.toe = ThelenTendonToe(c.fmax_tendon_strain);
    k.toe_scale = k.toe.toe_force / (std::exp(k.toe.toe_shape) - 1);
    k.toe_rate = k.toe.toe_shape / k.toe.toe_strain;
    k.passive_rate = c.kshape_passive / c.fmax_muscle_strain;
    k.inv_active_shape = 1 / c.kshape_active;
    k.inv_optimal = 1 / t.optimal_fiber_length;
    k.inv_slack = 1 / t.tendon_slack_length;
    k.eccentric = ThelenEccentricFactor(c);
    k.velocity_scale = t.max_contraction_velocity * t.optimal_fiber_length;
  }

  double Height() const { return height_; }  // optimal_fiber_length sin(pennation_angle) [m]

  double MinimumFiberLength() const {  // [m]
    return millard_ ? millard_->minimum_fiber_length() : minimum_fiber_length_;
  }

  // ThelenPassiveForceLength with the parameters' denominator
  double PassiveForceLength(double l) const {
    if (l <= 1) return 0;
    const ThelenCurveParameters& c = p_.thelen.curves;
    return (std::exp(c.kshape_passive * (l - 1) / c.fmax_muscle_strain) - 1) / passive_denominator_;
  }

  // normalised fibre force along the fibre needed by the tendon, and its derivative by lm
  struct Balance {
    double fse = 0, cos = 1, fal = 0, fpe = 0;  // [-]
    double num = 0, den = 1;                    // fv = num / den: fse / cos - fpe over a fal [-]
    double dnum = 0, dden = 0;                  // their derivatives by lm [1/m]
    double fv = 1;                              // [-]
    double dfv = 0;                             // [1/m]
  };

  // the curves of ThelenTendonForceStrain, ThelenActiveForceLength, PassiveForceLength and their
  // slopes, each pair from one exp() with the constants of UpdateThelenElasticConstants
  Balance BalanceAt(double lm, double path_length, double a) const {
    const ElasticConstants& k = elastic_constants_;
    const double h = Height();
    const double along = h > 0 ? std::sqrt(std::max(lm * lm - h * h, 0.0)) : lm;
    Balance b;
    b.cos = along / lm;
    const double strain = (path_length - along) * k.inv_slack - 1;
    double stiffness = 0;  // d fse / d strain [-]
    if (strain > k.toe.toe_strain) {
      b.fse = k.toe.linear_stiffness * (strain - k.toe.toe_strain) + k.toe.toe_force;
      stiffness = k.toe.linear_stiffness;
    } else if (strain > 0) {
      const double e = std::exp(k.toe_rate * strain);
      b.fse = k.toe_scale * (e - 1);
      stiffness = k.toe_scale * k.toe_rate * e;
    }
    const double l = lm * k.inv_optimal;
    const double stretch = l - 1;
    b.fal = std::exp(-stretch * stretch * k.inv_active_shape);
    const double dfal = -2 * stretch * k.inv_active_shape * b.fal;  // by l
    double dfpe = 0;                                                // by l
    if (stretch > 0) {
      const double e = std::exp(k.passive_rate * stretch);
      b.fpe = (e - 1) / passive_denominator_;
      dfpe = k.passive_rate * e / passive_denominator_;
    }
    const double cos = std::max(b.cos, 1e-12);
    const double inv_cos = 1 / cos;
    b.num = b.fse * inv_cos - b.fpe;
    b.den = std::max(a * b.fal, 1e-12);
    const double inv_den = 1 / b.den;
    b.fv = b.num * inv_den;
    const double dfse = -stiffness * k.inv_slack * inv_cos;
    const double dcos = h > 0 ? h * h / (lm * lm * lm * cos) : 0.0;
    b.dnum = (dfse - b.fse * dcos * inv_cos) * inv_cos - dfpe * k.inv_optimal;
    b.dden = a * dfal * k.inv_optimal;
    b.dfv = (b.dnum - b.fv * b.dden) * inv_den;
    return b;
  }

  // ThelenForceVelocityInverse and its slope together, with the cached eccentric factor: the
  // normalised fibre velocity [-] at force-velocity multiplier fv and its derivative by fv
  std::pair<double, double> InverseForceVelocity(double fv, double a) const {
    const ThelenCurveParameters& p = p_.thelen.curves;
    const double k = ThelenSpeedLimit(a);
    const double c = elastic_constants_.eccentric;
    if (fv <= 0) {
      const double slope = k * (1 + 1 / p.af);
      return {-k + slope * fv, slope};
    }
    if (fv <= 1) {
      const double d = 1 / (1 + fv / p.af);
      return {k * (fv - 1) * d, k * (1 + 1 / p.af) * d * d};
    }
    const double fv_thr = p.fv_linear_extrap_threshold * p.flen;
    if (fv < fv_thr) {
      const double d = 1 / (c * (p.flen - fv));
      return {k * (fv - 1) * d, k * (p.flen - 1) * d * d * c};
    }
    const double d = 1 / (c * (p.flen - fv_thr));
    const double slope = k * (p.flen - 1) * d * d * c;
    return {k * (fv_thr - 1) * d + slope * (fv - fv_thr), slope};
  }

  // fibre velocity [m/s] of the balance b at activation a, and its derivative by lm [1/s]
  std::pair<double, double> FiberVelocityOf(const Balance& b, double a) const {
    const auto [v, dv] = InverseForceVelocity(b.fv, a);
    const double scale = elastic_constants_.velocity_scale;
    return {v * scale, dv * b.dfv * scale};
  }

  // fibre velocity [m/s] from the force balance, and its derivative by lm [1/s]
  std::pair<double, double> FiberVelocity(double lm, double path_length, double a) const {
    return FiberVelocityOf(BalanceAt(lm, path_length, a), a);
  }

  // x with x = base + c g(x): root of R(x) = x - base - c g(x) above the shortest fibre
  double SolveStage(double base, double c, double path_length, double a) const {
    const double lo = MinimumFiberLength();
    auto residual = [&](double x) {
      const auto [g, dg] = FiberVelocity(x, path_length, a);
      return std::make_pair(x - base - c * g, 1 - c * dg);
    };
    if (residual(lo).first >= 0) return lo;
    double hi = std::max(base, lo * 1.001);
    for (int i = 0; i < 80 && residual(hi).first < 0; ++i) hi = lo + 2 * (hi - lo);
    return SafeNewton(residual, lo, hi, std::max(base, lo), 1e-13 * p_.thelen.optimal_fiber_length);
  }

  // SolveStage from a predicted root: plain Newton steps, which along a smooth path converge
  // quadratically in two or three evaluations; the bracketed SolveStage when a step would leave
  // the fibres' range, the residual's slope is not positive or 6 steps do not converge. The last
  // correction is below 1e-9 optimal fibre lengths, so the root is within the square of that
  // times the curvature: far below the 1e-13 of the bracketed solve.
  double SolveStageFrom(double guess, double base, double c, double path_length, double a) const {
    const double lo = MinimumFiberLength();
    const double tol = 1e-9 * p_.thelen.optimal_fiber_length;
    double x = guess;
    for (int i = 0; i < 6 && x > lo && std::isfinite(x); ++i) {
      const auto [g, dg] = FiberVelocity(x, path_length, a);
      const double slope = 1 - c * dg;
      if (!(slope > 0)) break;
      const double dx = (x - base - c * g) / slope;
      x -= dx;
      if (std::abs(dx) < tol && x > lo) return x;
    }
    return SolveStage(base, c, path_length, a);
  }

  // two-stage L-stable SDIRK (second order, stiffly accurate) over h; the path moves linearly
  // from l0 to l1 and the activation from a0 to a1. *velocity [m/s]: in, the fibre velocity at
  // the start (a guess: it only predicts the stage roots); out, the last stage's slope (the
  // fibre velocity at the end)
  double FiberStep(double lm, double l0, double l1, double a0, double a1, double h,
                   double* velocity) const {
    const double gamma = 1 - 1 / std::sqrt(2.0);
    const double x1 = SolveStageFrom(lm + gamma * h * *velocity, lm, gamma * h,
                                     l0 + gamma * (l1 - l0), a0 + gamma * (a1 - a0));
    const double k1 = (x1 - lm) / (gamma * h);
    const double base = lm + (1 - gamma) * h * k1;
    // the second stage predicted from k1 carried over the step
    const double x2 = SolveStageFrom(lm + h * k1, base, gamma * h, l1, a1);
    *velocity = (x2 - base) / (gamma * h);
    return x2;
  }

  // the fibre length of zero fibre velocity (fv = 1): tendon force = (a fal + fpe) cos
  double EquilibriumFiberLength(double path_length, double a) const {
    const ThelenMuscleParameters& t = p_.thelen;
    const double lo = MinimumFiberLength();
    const double h = Height();
    auto excess = [&](double x) {
      // isometric fibre force minus what the tendon pulls, normalised, along the fibre
      const Balance b = BalanceAt(x, path_length, a);
      return std::make_pair(b.den - b.num, b.dden - b.dnum);
    };
    if (excess(lo).first >= 0) return lo;
    const double slack = path_length - t.tendon_slack_length;
    double hi = std::sqrt(h * h + slack * slack);
    if (!(hi > lo)) return lo;
    for (int i = 0; i < 80 && excess(hi).first < 0; ++i) hi = lo + 2 * (hi - lo);
    return SafeNewton(excess, lo, hi, 0.5 * (lo + hi), 1e-14 * t.optimal_fiber_length);
  }

  // --- outputs at the end of a step

  void Evaluate(double path_length, double path_speed) {
    if (millard_)
      EvaluateMillard(path_length, path_speed);
    else if (curves_ == Curves::kMujoco)
      EvaluateMujoco(path_length, path_speed);
    else if (elastic_)
      EvaluateThelenElastic(path_length);
    else
      EvaluateThelenRigid(path_length, path_speed);
  }

  void EvaluateMujoco(double length, double speed) {
    const MujocoMuscleParameters& m = p_.mujoco;
    const double L0 = MujocoL0();
    const double F0 = MujocoF0();
    Outputs o;
    o.norm_fiber_length =
        MujocoNormalizedLength(length, m.lengthrange_lo, m.lengthrange_hi, m.range0, m.range1);
    o.fiber_length = o.norm_fiber_length * L0;
    o.fiber_velocity = speed;
    o.norm_fiber_velocity = speed / std::max(kMinVal, L0 * m.vmax);
    o.active_force_length = MujocoActiveForceLength(o.norm_fiber_length, m.lmin, m.lmax);
    o.force_velocity = MujocoForceVelocity(o.norm_fiber_velocity, m.fvmax);
    o.passive_force_length = MujocoPassiveForceLength(o.norm_fiber_length, m.lmax, m.fpmax);
    o.active_fiber_force = F0 * activation_ * o.active_force_length * o.force_velocity;
    o.passive_force = F0 * o.passive_force_length;
    o.tension = std::max(0.0, o.active_fiber_force + o.passive_force);
    out_ = o;
  }

  void EvaluateThelenRigid(double length, double speed) {
    const ThelenMuscleParameters& t = p_.thelen;
    const double along = length - t.tendon_slack_length;
    Outputs o;
    o.tendon_length = t.tendon_slack_length;
    const double straight = std::max(along, 0.0);
    o.fiber_length = std::sqrt(height_ * height_ + straight * straight);  // PennatedFiberLength
    const double cos = along > 0 && o.fiber_length > 0 ? along / o.fiber_length : 0.0;
    o.pennation_cos = along > 0 ? cos : -1;
    o.fiber_velocity = cos * speed;
    FillThelenForces(&o, t.max_isometric_force, cos);
    out_ = o;
  }

  void EvaluateThelenElastic(double length) {
    const ThelenMuscleParameters& t = p_.thelen;
    const double lm = std::max(fiber_length_, MinimumFiberLength());
    const Balance b = BalanceAt(lm, length, activation_);
    Outputs o;
    o.fiber_length = lm;
    o.pennation_cos = Clamp(b.cos, 0, 1);
    o.tendon_length = length - lm * b.cos;
    o.tendon_strain = o.tendon_length / t.tendon_slack_length - 1;
    o.fiber_velocity = FiberVelocityOf(b, activation_).first;
    o.norm_fiber_length = lm / t.optimal_fiber_length;
    o.norm_fiber_velocity =
        o.fiber_velocity / (t.max_contraction_velocity * t.optimal_fiber_length);
    o.active_force_length = b.fal;
    o.force_velocity = b.fv;
    o.passive_force_length = b.fpe;
    o.active_fiber_force = t.max_isometric_force * activation_ * b.fal * b.fv;
    o.passive_force = t.max_isometric_force * b.fpe;
    o.tension = t.max_isometric_force * b.fse;
    out_ = o;
  }

  void FillThelenForces(Outputs* o, double f0, double cos) const {
    const ThelenMuscleParameters& t = p_.thelen;
    o->norm_fiber_length = o->fiber_length / t.optimal_fiber_length;
    o->norm_fiber_velocity =
        o->fiber_velocity / (t.max_contraction_velocity * t.optimal_fiber_length);
    o->active_force_length = ThelenActiveForceLength(o->norm_fiber_length, t.curves.kshape_active);
    o->passive_force_length = PassiveForceLength(o->norm_fiber_length);
    o->force_velocity = ThelenForceVelocity(o->norm_fiber_velocity, activation_, t.curves);
    o->active_fiber_force = f0 * activation_ * o->active_force_length * o->force_velocity;
    o->passive_force = f0 * o->passive_force_length;
    o->tension = std::max(0.0, (o->active_fiber_force + o->passive_force) * cos);
  }

  // --- Millard 2012 (millard.cc: the curves and the fibre-tendon balance)

  // the fibre length at rest (fibre velocity 0): a fal + fpe = fse / cos
  double MillardEquilibrium(double path_length, double a) const {
    const MillardFiberModel& m = *millard_;
    const double lo = m.minimum_fiber_length();
    auto excess = [&](double x) { return m.IsometricExcess(x, path_length, a); };
    if (excess(lo).first >= 0) return lo;
    // a fibre that leaves the tendon slack pulls at least what the tendon does (nothing)
    const double slack = path_length - p_.millard.tendon_slack_length;
    double hi = std::sqrt(m.height() * m.height() + slack * slack);
    if (!(hi > lo)) return lo;
    for (int i = 0; i < 80 && excess(hi).first < 0; ++i) hi = lo + 2 * (hi - lo);
    return SafeNewton(excess, lo, hi, 0.5 * (lo + hi), 1e-14 * p_.millard.optimal_fiber_length);
  }

  // the stage equation x = base + c v(x) of the SDIRK below, v the fibre velocity of the balance
  // at this stage's path length and activation: Newton from the predicted root, the bracketed
  // solve when a step would leave the fibres' range or 6 steps do not converge
  double MillardStage(double guess, double base, double c, double path_length, double a) const {
    const MillardFiberModel& m = *millard_;
    const double lo = m.minimum_fiber_length();
    auto residual = [&](double x) {
      const auto [v, dv] = m.FiberVelocity(x, path_length, a);
      return std::make_pair(x - base - c * v, 1 - c * dv);
    };
    // a correction below 1e-10 optimal lengths leaves an error of its square times the curvature
    const double tol = 1e-10 * p_.millard.optimal_fiber_length;
    double x = guess;
    for (int i = 0; i < 6 && x > lo && std::isfinite(x); ++i) {
      const auto [r, slope] = residual(x);
      if (!(slope > 0)) break;
      const double dx = r / slope;
      x -= dx;
      if (std::abs(dx) < tol && x > lo) return x;
    }
    if (residual(lo).first >= 0) return lo;
    double hi = std::max(base, lo * 1.001);
    for (int i = 0; i < 80 && residual(hi).first < 0; ++i) hi = lo + 2 * (hi - lo);
    return SafeNewton(residual, lo, hi, std::max(base, lo),
                      1e-13 * p_.millard.optimal_fiber_length);
  }

  // elastic tendon: the activation exact, the fibre length by the two-stage L-stable SDIRK
  // (second order) in sub-steps of <= 1 ms, each stage at its own time's path length and
  // activation (the path moves linearly through the step)
  double StepMillardElastic(double path_length, double path_speed, double dt) {
    const int n = FiberSubsteps(dt);
    const double h = dt / n;
    const double gamma = 1 - 1 / std::sqrt(2.0);
    double lm = std::max(fiber_length_, MinimumFiberLength());
    double velocity = out_.fiber_velocity;  // predicts the stage roots
    for (int i = 0; i < n; ++i) {
      const double a0 = activation_;
      const double l0 = path_length + path_speed * i * h;
      const double a_stage = IntegrateActivation(a0, gamma * h);
      activation_ = IntegrateActivation(a0, h);
      const double x1 = MillardStage(lm + gamma * h * velocity, lm, gamma * h,
                                     l0 + gamma * h * path_speed, a_stage);
      const double k1 = (x1 - lm) / (gamma * h);
      const double base = lm + (1 - gamma) * h * k1;
      const double x2 =
          MillardStage(lm + h * k1, base, gamma * h, l0 + h * path_speed, activation_);
      velocity = (x2 - base) / (gamma * h);
      lm = x2;
    }
    fiber_length_ = lm;
    Evaluate(path_length + path_speed * dt, path_speed);
    return out_.tension;
  }

  void EvaluateMillard(double path_length, double path_speed) {
    const MillardFiberModel::State s =
        elastic_ ? millard_->Elastic(std::max(fiber_length_, MinimumFiberLength()), path_length,
                                     activation_)
                 : millard_->Rigid(path_length, path_speed, activation_);
    Outputs o;
    o.fiber_length = s.fiber_length;
    o.fiber_velocity = s.fiber_velocity;
    o.norm_fiber_length = s.norm_fiber_length;
    o.norm_fiber_velocity = s.norm_fiber_velocity;
    o.pennation_cos = s.cos_pennation;
    o.tendon_length = s.tendon_length;
    o.tendon_strain = s.tendon_strain;
    o.active_force_length = s.active_force_length;
    o.force_velocity = s.force_velocity;
    o.passive_force_length = s.passive_force_length;
    o.active_fiber_force = s.active_fiber_force;
    o.passive_force = s.passive_force;
    o.tension = s.tension;
    out_ = o;
  }

  static constexpr std::size_t kOutputValues = sizeof(Outputs) / sizeof(double);
  static_assert(sizeof(Outputs) == kOutputValues * sizeof(double) &&
                    std::is_trivially_copyable_v<Outputs>,
                "Outputs is saved as plain doubles");

  std::string name_;
  Curves curves_;
  bool elastic_;
  AllParameters p_;
  double height_ = 0;                // optimal_fiber_length sin(pennation_angle) [m]
  double minimum_fiber_length_ = 0;  // [m]
  double passive_denominator_ = 1;   // exp(kshape_passive) - 1 [-]
  double excitation_ = 0;            // command u [-], in [0, 1]
  CommandDelay delay_;               // its way to the muscle (command_delay)
  double activation_ = 0;            // [-]
  double fiber_length_ = 0;          // elastic tendon state [m]
  // the elastic-tendon curve constants (Thelen), once per parameter change
  struct ElasticConstants {
    ThelenTendonConstants toe;
    double toe_scale = 0;         // toe_force / (exp(toe_shape) - 1) [-]
    double toe_rate = 0;          // toe_shape / toe_strain [-]
    double passive_rate = 0;      // kshape_passive / fmax_muscle_strain [-]
    double inv_active_shape = 0;  // 1 / kshape_active [-]
    double inv_optimal = 0;       // 1 / optimal_fiber_length [1/m]
    double inv_slack = 0;         // 1 / tendon_slack_length [1/m]
    double eccentric = 0;         // ThelenEccentricFactor [-]
    double velocity_scale = 0;    // max_contraction_velocity optimal_fiber_length [m/s]
  };
  ElasticConstants elastic_constants_;  // UpdateThelenElasticConstants
  Outputs out_;
  std::unique_ptr<MillardFiberModel> millard_;  // curves=millard2012: curves built per change

 public:
  bool mujoco_integrator_ = false;   // options["integrator"] = "mujoco"
};

std::unique_ptr<TendonActuator> MakeHillMuscle(const sgal::Actuator& a) {
  const std::string where = "actuator '" + a.name + "' (hill_muscle): ";
  for (const auto& [key, value] : a.options)
    if (key != "curves" && key != "tendon" && key != "integrator")
      throw std::invalid_argument(where + "unknown option '" + key +
                                  "' (known: curves, tendon, integrator)");
  Curves curves = Curves::kThelen;
  if (const auto it = a.options.find("curves"); it != a.options.end()) {
    if (it->second == "mujoco")
      curves = Curves::kMujoco;
    else if (it->second == "millard2012")
      curves = Curves::kMillard;
    else if (it->second != "thelen2003")
      throw std::invalid_argument(where + "unknown curves '" + it->second +
                                  "' (known: thelen2003, mujoco, millard2012)");
  }
  bool elastic = false;
  if (const auto it = a.options.find("tendon"); it != a.options.end()) {
    if (it->second == "elastic")
      elastic = true;
    else if (it->second != "rigid")
      throw std::invalid_argument(where + "unknown tendon '" + it->second +
                                  "' (known: rigid, elastic)");
  }
  if (elastic && curves == Curves::kMujoco)
    throw std::invalid_argument(where +
                                "tendon=elastic needs curves=thelen2003 or millard2012 (MuJoCo's "
                                "muscle has a rigid tendon)");
  AllParameters p;
  std::set<std::string> given;
  for (const auto& [name, value] : a.parameters) given.insert(name);
  // a name may have one entry per curve set (thelen2003 and millard2012 share names)
  std::set<std::string> applicable;
  for (const auto& e : ParameterTable())
    if (AppliesTo(e.applies, curves)) applicable.insert(e.name);
  for (const auto& e : ParameterTable()) {
    const bool applies = AppliesTo(e.applies, curves);
    if (given.count(e.name) && !applicable.count(e.name))
      throw std::invalid_argument(where + "parameter '" + e.name +
                                  "' does not apply to curves=" + CurvesName(curves));
    if (applies && e.required && !given.count(e.name))
      throw std::invalid_argument(where + "missing parameter '" + e.name + "' [" + e.unit +
                                  "] needed by curves=" + CurvesName(curves) + ": " + e.help);
    if (applies && given.count(e.name)) e.ref(p) = a.parameters.at(e.name);
  }
  try {
    HillMuscle::ValidateAll(p, curves, elastic);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(where + error.what());
  }
  auto muscle = std::make_unique<HillMuscle>(a.name, curves, elastic, p);
  muscle->Set("command_delay", ParameterOr(a, "command_delay", 0));
  if (const auto it = a.options.find("integrator"); it != a.options.end()) {
    if (it->second == "mujoco") {
      if (elastic)
        throw std::invalid_argument(where + "integrator=mujoco needs a rigid tendon");
      if (curves == Curves::kMillard)
        throw std::invalid_argument(where + "integrator=mujoco needs curves=thelen2003 or mujoco");
      muscle->mujoco_integrator_ = true;
    } else if (it->second != "exact") {
      throw std::invalid_argument(where + "unknown integrator '" + it->second +
                                  "' (known: exact, mujoco)");
    }
  }
  return muscle;
}

}  // namespace

void RegisterMuscleKinds() {
  std::vector<ParameterSpec> specs;
  AllParameters defaults;
  for (const auto& e : ParameterTable()) {
    // a name shared by two curve sets is one parameter: the first entry's default, both helps
    const auto same = std::find_if(specs.begin(), specs.end(),
                                   [&](const ParameterSpec& s) { return s.name == e.name; });
    if (same == specs.end())
      specs.push_back({e.name, e.unit, e.ref(defaults), false, e.help});
    else
      same->help += "; " + std::string(e.help);
  }
  specs.push_back({"command_delay", "s", 0, false,
                   "time from an excitation command to the muscle (a nerve's conduction), "
                   "rounded to whole time steps (at most 100,000 of them)"});
  RegisterKind("hill_muscle", std::move(specs), MakeHillMuscle);
}

}  // namespace caliper::actuators
