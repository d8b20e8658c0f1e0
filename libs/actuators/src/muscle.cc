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
#include "muscle_validation.h"

namespace caliper::actuators {

namespace {

constexpr double kMinVal = 1e-15;     // MuJoCo's mjMINVAL
constexpr double kMaxSubstep = 1e-3;  // [s]
constexpr double kPi = 3.14159265358979323846;

using muscle_detail::Num;

double Clamp(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }

// shortening speed limit of Thelen's curve at activation a [normalised]
double ThelenSpeedLimit(double activation) { return 0.25 + 0.75 * Clamp(activation, 0, 1); }

double ThelenEccentricFactor(const ThelenCurveParameters& p) {
  return (2 + 2 / p.af) / (p.flen - 1);
}

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

}  // namespace

// ---------------------------------------------------------------------------------------------
// Thelen curves

double ThelenActiveForceLength(double l, double kshape_active) {
  return std::exp(-(l - 1) * (l - 1) / kshape_active);
}

double ThelenPassiveForceLength(double l, double kshape_passive, double fmax_muscle_strain) {
  if (l <= 1) return 0;
  return (std::exp(kshape_passive * (l - 1) / fmax_muscle_strain) - 1) /
         (std::exp(kshape_passive) - 1);
}

ThelenTendonConstants ThelenTendonToe(double e0) {
  ThelenTendonConstants c;
  const double e3 = std::exp(3.0);
  c.toe_strain = 99 * e0 * e3 / (166 * e3 - 67);
  c.linear_stiffness = 0.67 / (e0 - c.toe_strain);
  return c;
}

double ThelenTendonForceStrain(double strain, double fmax_tendon_strain) {
  const ThelenTendonConstants c = ThelenTendonToe(fmax_tendon_strain);
  if (strain > c.toe_strain) return c.linear_stiffness * (strain - c.toe_strain) + c.toe_force;
  if (strain > 0)
    return c.toe_force / (std::exp(c.toe_shape) - 1) *
           (std::exp(c.toe_shape * strain / c.toe_strain) - 1);
  return 0;
}

double ThelenTendonStiffness(double strain, double fmax_tendon_strain) {
  const ThelenTendonConstants c = ThelenTendonToe(fmax_tendon_strain);
  if (strain > c.toe_strain) return c.linear_stiffness;
  if (strain > 0)
    return c.toe_force / (std::exp(c.toe_shape) - 1) * c.toe_shape / c.toe_strain *
           std::exp(c.toe_shape * strain / c.toe_strain);
  return 0;
}

double ThelenForceVelocityInverse(double fv, double activation, const ThelenCurveParameters& p) {
  const double k = ThelenSpeedLimit(activation);
  const double c = ThelenEccentricFactor(p);
  const double fv_thr = p.fv_linear_extrap_threshold * p.flen;
  // below zero force: the tangent at fv = 0
  if (fv <= 0) return -k + k * (1 + 1 / p.af) * fv;
  if (fv <= 1) return k * (fv - 1) / (1 + fv / p.af);
  if (fv < fv_thr) return k * (fv - 1) / (c * (p.flen - fv));
  // beyond the threshold: the tangent there
  const double v_thr = k * (fv_thr - 1) / (c * (p.flen - fv_thr));
  const double s_thr = k * (p.flen - 1) / (c * (p.flen - fv_thr) * (p.flen - fv_thr));
  return v_thr + s_thr * (fv - fv_thr);
}

double ThelenForceVelocityInverseSlope(double fv, double activation,
                                       const ThelenCurveParameters& p) {
  const double k = ThelenSpeedLimit(activation);
  const double c = ThelenEccentricFactor(p);
  const double fv_thr = p.fv_linear_extrap_threshold * p.flen;
  if (fv <= 0) return k * (1 + 1 / p.af);
  if (fv <= 1) {
    const double d = 1 + fv / p.af;
    return k * (1 + 1 / p.af) / (d * d);
  }
  const double f = std::min(fv, fv_thr);
  return k * (p.flen - 1) / (c * (p.flen - f) * (p.flen - f));
}

double ThelenForceVelocity(double v, double activation, const ThelenCurveParameters& p) {
  const double k = ThelenSpeedLimit(activation);
  if (v <= -k) return (v + k) / (k * (1 + 1 / p.af));
  if (v <= 0) return (k + v) / (k - v / p.af);
  const double c = ThelenEccentricFactor(p);
  const double fv_thr = p.fv_linear_extrap_threshold * p.flen;
  const double v_thr = k * (fv_thr - 1) / (c * (p.flen - fv_thr));
  if (v < v_thr) return (k + v * c * p.flen) / (k + v * c);
  const double s_thr = k * (p.flen - 1) / (c * (p.flen - fv_thr) * (p.flen - fv_thr));
  return fv_thr + (v - v_thr) / s_thr;
}

double ActivationRate(double excitation, double activation, double activation_time_constant,
                      double deactivation_time_constant, double minimum_activation) {
  const double u = Clamp(excitation, minimum_activation, 1);
  const double a = Clamp(activation, minimum_activation, 1);
  const double tau = u > a ? activation_time_constant * (0.5 + 1.5 * a)
                           : deactivation_time_constant / (0.5 + 1.5 * a);
  return (u - a) / tau;
}

double PennatedFiberLength(double along, double optimal_fiber_length, double pennation_at_optimal) {
  const double h = optimal_fiber_length * std::sin(pennation_at_optimal);
  return std::sqrt(h * h + along * along);
}

double PennationAngle(double fiber_length, double optimal_fiber_length,
                      double pennation_at_optimal) {
  const double h = optimal_fiber_length * std::sin(pennation_at_optimal);
  if (h <= 0) return 0;
  if (fiber_length <= h) return kPi / 2;
  return std::asin(h / fiber_length);
}

// ---------------------------------------------------------------------------------------------
// MuJoCo curves

double MujocoActiveForceLength(double L, double lmin, double lmax) {
  if (L < lmin || L > lmax) return 0;
  const double a = 0.5 * (lmin + 1);
  const double b = 0.5 * (1 + lmax);
  if (L <= a) {
    const double x = (L - lmin) / std::max(kMinVal, a - lmin);
    return 0.5 * x * x;
  }
  if (L <= 1) {
    const double x = (1 - L) / std::max(kMinVal, 1 - a);
    return 1 - 0.5 * x * x;
  }
  if (L <= b) {
    const double x = (L - 1) / std::max(kMinVal, b - 1);
    return 1 - 0.5 * x * x;
  }
  const double x = (lmax - L) / std::max(kMinVal, lmax - b);
  return 0.5 * x * x;
}

double MujocoForceVelocity(double V, double fvmax) {
  const double y = fvmax - 1;
  if (V <= -1) return 0;
  if (V <= 0) return (V + 1) * (V + 1);
  if (V <= y) return fvmax - (y - V) * (y - V) / std::max(kMinVal, y);
  return fvmax;
}

double MujocoPassiveForceLength(double L, double lmax, double fpmax) {
  const double b = 0.5 * (1 + lmax);
  if (L <= 1) return 0;
  if (L <= b) {
    const double x = (L - 1) / std::max(kMinVal, b - 1);
    return fpmax * 0.5 * x * x;
  }
  const double x = (L - b) / std::max(kMinVal, b - 1);
  return fpmax * (0.5 + x);
}

double MujocoActivationRate(double ctrl, double act, double tau_act, double tau_deact) {
  const double u = Clamp(ctrl, 0, 1);
  const double a = Clamp(act, 0, 1);
  const double tau = u > act ? tau_act * (0.5 + 1.5 * a) : tau_deact / (0.5 + 1.5 * a);
  return (u - act) / std::max(kMinVal, tau);
}

double MujocoOptimalLength(double lengthrange_lo, double lengthrange_hi, double range0,
                           double range1) {
  return (lengthrange_hi - lengthrange_lo) / std::max(kMinVal, range1 - range0);
}

double MujocoNormalizedLength(double length, double lengthrange_lo, double lengthrange_hi,
                              double range0, double range1) {
  const double L0 = MujocoOptimalLength(lengthrange_lo, lengthrange_hi, range0, range1);
  return range0 + (length - lengthrange_lo) / std::max(kMinVal, L0);
}

double MujocoForceScale(double force, double scale, double acc0) {
  return force < 0 ? scale / std::max(kMinVal, acc0) : force;
}

// ---------------------------------------------------------------------------------------------
// parameter validation

using muscle_detail::Require;

void Validate(const ThelenMuscleParameters& p, bool elastic_tendon) {
  const ThelenCurveParameters& c = p.curves;
  muscle_detail::RequireHillCommon(p, elastic_tendon);
  if (elastic_tendon)
    Require(p.minimum_activation > 0 && p.minimum_activation < 1, "minimum_activation",
            p.minimum_activation,
            "must be in (0, 1) with an elastic tendon (the fibre velocity is singular at 0)");
  else
    Require(p.minimum_activation >= 0 && p.minimum_activation < 1, "minimum_activation",
            p.minimum_activation, "must be in [0, 1)");
  Require(c.kshape_active > 0, "kshape_active", c.kshape_active, "must be > 0");
  Require(c.kshape_passive > 0, "kshape_passive", c.kshape_passive, "must be > 0");
  Require(c.fmax_muscle_strain > 0, "fmax_muscle_strain", c.fmax_muscle_strain, "must be > 0");
  Require(c.fmax_tendon_strain > 0, "fmax_tendon_strain", c.fmax_tendon_strain, "must be > 0");
  Require(c.af > 0, "af", c.af, "must be > 0");
  Require(c.flen > 1, "flen", c.flen, "must be > 1");
  Require(c.fv_linear_extrap_threshold > 1 / c.flen && c.fv_linear_extrap_threshold < 1,
          "fv_linear_extrap_threshold", c.fv_linear_extrap_threshold,
          "must be in (1/flen = " + Num(1 / c.flen) + ", 1)");
}

void Validate(const MujocoMuscleParameters& p) {
  Require(std::isfinite(p.range1) && p.range0 < p.range1, "range0", p.range0,
          "must be < range1 = " + Num(p.range1));
  Require(p.lmin > 0 && p.lmin < 1, "lmin", p.lmin, "must be in (0, 1)");
  Require(p.lmax > 1, "lmax", p.lmax, "must be > 1");
  Require(p.vmax > 0, "vmax", p.vmax, "must be > 0 L0/s");
  Require(p.fpmax >= 0, "fpmax", p.fpmax, "must be >= 0");
  Require(p.fvmax >= 1, "fvmax", p.fvmax, "must be >= 1");
  Require(std::isfinite(p.lengthrange_lo) && p.lengthrange_lo < p.lengthrange_hi, "lengthrange_hi",
          p.lengthrange_hi, "must be > lengthrange_lo = " + Num(p.lengthrange_lo) + " m");
  Require(std::isfinite(p.force), "force", p.force, "must be finite");
  if (p.force < 0) {
    Require(p.scale >= 0, "scale", p.scale, "must be >= 0 (force < 0 uses scale / acc0)");
    Require(p.acc0 > 0, "acc0", p.acc0, "must be > 0 when force < 0 (F0 = scale / acc0)");
  }
  Require(p.tau_act > 0, "tau_act", p.tau_act, "must be > 0 s");
  Require(p.tau_deact > 0, "tau_deact", p.tau_deact, "must be > 0 s");
}

// ---------------------------------------------------------------------------------------------
// the kind hill_muscle

namespace {

enum class Curves { kThelen, kMujoco, kMillard };

struct AllParameters {
  ThelenMuscleParameters thelen;
  MujocoMuscleParameters mujoco;
  MillardMuscleParameters millard;
  double default_activation = 0;  // [-]
};

enum class Applies { kBoth, kThelen, kMujoco, kMillard };  // kBoth: every curve set

struct ParameterEntry {
  const char* name;
  const char* unit;
  Applies applies;
  bool required;
  double& (*ref)(AllParameters&);
  const char* help;
};

const std::vector<ParameterEntry>& ParameterTable() {
  using P = AllParameters;
  static const std::vector<ParameterEntry> table = {
      {"default_activation", "", Applies::kBoth, false,
       [](P& p) -> double& { return p.default_activation; },
       "activation at Reset, in [0, 1] (raised to minimum_activation)"},
      // thelen2003
      {"max_isometric_force", "N", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.max_isometric_force; }, "F0 (thelen2003)"},
      {"optimal_fiber_length", "m", Applies::kThelen, true,
       [](P& p) -> double& { return p.thelen.optimal_fiber_length; },
       "fibre length of maximum active force (thelen2003, required)"},
      {"tendon_slack_length", "m", Applies::kThelen, true,
       [](P& p) -> double& { return p.thelen.tendon_slack_length; },
       "tendon length below which it carries no force (thelen2003, required)"},
      {"pennation_angle", "rad", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.pennation_angle; },
       "pennation at optimal fibre length; constant muscle thickness (thelen2003)"},
      {"max_contraction_velocity", "1/s", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.max_contraction_velocity; },
       "in optimal fibre lengths per second (thelen2003)"},
      {"activation_time_constant", "s", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.activation_time_constant; }, "(thelen2003)"},
      {"deactivation_time_constant", "s", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.deactivation_time_constant; }, "(thelen2003)"},
      {"minimum_activation", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.minimum_activation; },
       "lower bound of the activation (thelen2003; > 0 with an elastic tendon)"},
      {"maximum_pennation_angle", "rad", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.maximum_pennation_angle; },
       "sets the shortest fibre, height / sin(maximum) (thelen2003)"},
      {"kshape_active", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.kshape_active; },
       "gamma of the active force-length Gaussian (thelen2003)"},
      {"kshape_passive", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.kshape_passive; },
       "passive force-length exponent (thelen2003)"},
      {"fmax_muscle_strain", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.fmax_muscle_strain; },
       "fibre strain of passive force F0 (thelen2003)"},
      {"fmax_tendon_strain", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.fmax_tendon_strain; },
       "tendon strain of force F0 (thelen2003)"},
      {"af", "", Applies::kThelen, false, [](P& p) -> double& { return p.thelen.curves.af; },
       "force-velocity shape factor (thelen2003)"},
      {"flen", "", Applies::kThelen, false, [](P& p) -> double& { return p.thelen.curves.flen; },
       "maximum lengthening force / F0 (thelen2003)"},
      {"fv_linear_extrap_threshold", "", Applies::kThelen, false,
       [](P& p) -> double& { return p.thelen.curves.fv_linear_extrap_threshold; },
       "force-velocity linear beyond this * flen (thelen2003)"},
      // mujoco
      {"range0", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.range0; },
       "normalised length at lengthrange_lo (mujoco)"},
      {"range1", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.range1; },
       "normalised length at lengthrange_hi (mujoco)"},
      {"force", "N", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.force; },
       "F0; < 0: scale / acc0 (mujoco)"},
      {"scale", "rad/s^2", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.scale; },
       "F0 = scale / acc0 when force < 0 (mujoco)"},
      {"acc0", "rad/s^2/N", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.acc0; },
       "joint acceleration norm of a unit actuator force, from MuJoCo's compiler (mujoco)"},
      {"lmin", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.lmin; },
       "shortest normalised length with active force (mujoco)"},
      {"lmax", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.lmax; },
       "longest normalised length with active force (mujoco)"},
      {"vmax", "1/s", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.vmax; },
       "shortening speed of zero force, in L0 per second (mujoco)"},
      {"fpmax", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.fpmax; },
       "passive force / F0 is fpmax / 2 at (1 + lmax) / 2, linear beyond (mujoco)"},
      {"fvmax", "", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.fvmax; },
       "lengthening force limit / F0 (mujoco)"},
      {"lengthrange_lo", "m", Applies::kMujoco, true,
       [](P& p) -> double& { return p.mujoco.lengthrange_lo; },
       "actuator length mapped to range0 (mujoco, required)"},
      {"lengthrange_hi", "m", Applies::kMujoco, true,
       [](P& p) -> double& { return p.mujoco.lengthrange_hi; },
       "actuator length mapped to range1 (mujoco, required)"},
      {"tau_act", "s", Applies::kMujoco, false, [](P& p) -> double& { return p.mujoco.tau_act; },
       "activation time constant (mujoco)"},
      {"tau_deact", "s", Applies::kMujoco, false,
       [](P& p) -> double& { return p.mujoco.tau_deact; }, "deactivation time constant (mujoco)"},
      // millard2012: the names shared with thelen2003 are separate entries (own defaults)
      {"max_isometric_force", "N", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.max_isometric_force; }, "F0 (millard2012)"},
      {"optimal_fiber_length", "m", Applies::kMillard, true,
       [](P& p) -> double& { return p.millard.optimal_fiber_length; },
       "fibre length of maximum active force (millard2012, required)"},
      {"tendon_slack_length", "m", Applies::kMillard, true,
       [](P& p) -> double& { return p.millard.tendon_slack_length; },
       "tendon length below which it carries no force (millard2012, required)"},
      {"pennation_angle", "rad", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.pennation_angle; },
       "pennation at optimal fibre length; constant muscle thickness (millard2012)"},
      {"max_contraction_velocity", "1/s", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.max_contraction_velocity; },
       "in optimal fibre lengths per second (millard2012)"},
      {"activation_time_constant", "s", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.activation_time_constant; }, "(millard2012: 0.010)"},
      {"deactivation_time_constant", "s", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.deactivation_time_constant; },
       "(millard2012: 0.040)"},
      {"minimum_activation", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.minimum_activation; },
       "lower bound of the activation (millard2012)"},
      {"maximum_pennation_angle", "rad", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.maximum_pennation_angle; },
       "sets the shortest fibre with min_norm_active_fiber_length (millard2012)"},
      {"fiber_damping", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.fiber_damping; },
       "beta: fibre force F0 beta v / (vmax lopt) (millard2012)"},
      {"min_norm_active_fiber_length", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.min_norm_active_fiber_length; },
       "left shoulder of the active force-length curve (millard2012)"},
      {"transition_norm_fiber_length", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.transition_norm_fiber_length; },
       "steep to shallow ascending limb (millard2012)"},
      {"max_norm_active_fiber_length", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.max_norm_active_fiber_length; },
       "right shoulder of the active force-length curve (millard2012)"},
      {"shallow_ascending_slope", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.shallow_ascending_slope; },
       "active force-length slope of the shallow limb (millard2012)"},
      {"minimum_value", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.minimum_value; },
       "active force-length value at and beyond the shoulders (millard2012)"},
      {"concentric_slope_at_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.concentric_slope_at_vmax; },
       "force-velocity slope at -vmax (millard2012)"},
      {"concentric_slope_near_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.concentric_slope_near_vmax; },
       "force-velocity slope at -0.9 vmax (millard2012)"},
      {"isometric_slope", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.isometric_slope; },
       "force-velocity slope at 0 (millard2012)"},
      {"eccentric_slope_at_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.eccentric_slope_at_vmax; },
       "force-velocity slope at +vmax (millard2012)"},
      {"eccentric_slope_near_vmax", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.eccentric_slope_near_vmax; },
       "force-velocity slope at +0.9 vmax (millard2012)"},
      {"max_eccentric_velocity_force_multiplier", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.max_eccentric_velocity_force_multiplier; },
       "force-velocity value at +vmax (millard2012)"},
      {"concentric_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.concentric_curviness; },
       "force-velocity bend below 0, 0..1 (millard2012)"},
      {"eccentric_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.eccentric_curviness; },
       "force-velocity bend above 0, 0..1 (millard2012)"},
      {"fiber_strain_at_zero_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_strain_at_zero_force; },
       "passive fibre curve (millard2012)"},
      {"fiber_strain_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_strain_at_one_norm_force; },
       "passive fibre curve (millard2012)"},
      {"fiber_stiffness_at_low_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_stiffness_at_low_force; },
       "passive fibre curve (millard2012)"},
      {"fiber_stiffness_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_stiffness_at_one_norm_force; },
       "passive fibre curve; OpenSim's default 2 / strain at one (millard2012)"},
      {"fiber_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.fiber_curviness; },
       "passive fibre curve bend, 0..1 (millard2012)"},
      {"tendon_strain_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_strain_at_one_norm_force; },
       "tendon curve (millard2012)"},
      {"tendon_stiffness_at_one_norm_force", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_stiffness_at_one_norm_force; },
       "tendon curve; OpenSim's default 1.375 / strain at one (millard2012)"},
      {"tendon_norm_force_at_toe_end", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_norm_force_at_toe_end; },
       "tendon curve (millard2012)"},
      {"tendon_curviness", "", Applies::kMillard, false,
       [](P& p) -> double& { return p.millard.curves.tendon_curviness; },
       "tendon curve bend, 0..1 (millard2012)"},
  };
  return table;
}

bool AppliesTo(Applies applies, Curves curves) {
  return applies == Applies::kBoth || (applies == Applies::kThelen && curves == Curves::kThelen) ||
         (applies == Applies::kMujoco && curves == Curves::kMujoco) ||
         (applies == Applies::kMillard && curves == Curves::kMillard);
}

const char* CurvesName(Curves c) {
  return c == Curves::kThelen ? "thelen2003" : c == Curves::kMujoco ? "mujoco" : "millard2012";
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
    if (mujoco_integrator_) {
      // MuJoCo's order: the force of the current state, then act += dt * act_dot
      Evaluate(path_length, path_speed);
      const bool thelen = curves_ == Curves::kThelen;
      const double rate =
          ActivationRate(excitation_, activation_,
                         thelen ? p_.thelen.activation_time_constant : p_.mujoco.tau_act,
                         thelen ? p_.thelen.deactivation_time_constant : p_.mujoco.tau_deact,
                         MinimumActivation());
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
  // from these in every step)
  std::size_t StateSize() const override { return 2 + kOutputValues; }
  void SaveState(double* out) const override {
    out[0] = activation_;
    out[1] = fiber_length_;
    std::memcpy(out + 2, &out_, sizeof out_);
  }
  void RestoreState(const double* in) override {
    activation_ = in[0];
    fiber_length_ = in[1];
    std::memcpy(static_cast<void*>(&out_), in + 2, sizeof out_);
  }

  void SetTimeStep(double dt) override {
    if (!(dt > 0) || !std::isfinite(dt))
      throw std::invalid_argument(Prefix() + "time step " + Num(dt) + " s must be > 0");
    if (elastic_) FiberSubsteps(dt);  // throws when there would be too many
  }

  void SetCommand(double value) override {
    CheckFinite("excitation", value);
    excitation_ = Clamp(value, 0, 1);
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
    q.push_back({"excitation", "", true, false});
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

  double Get(const std::string& name) const override {
    for (const auto& e : ParameterTable())
      if (e.name == name && AppliesTo(e.applies, curves_)) {
        AllParameters copy = p_;
        return e.ref(copy);
      }
    if (curves_ == Curves::kMujoco && name == "max_isometric_force") return MujocoF0();
    if (curves_ == Curves::kMujoco && name == "optimal_fiber_length") return MujocoL0();
    if (name == "excitation") return excitation_;
    if (name == "activation") return activation_;
    if (name == "fiber_length") return elastic_ ? fiber_length_ : out_.fiber_length;
    if (name == "fiber_velocity") return out_.fiber_velocity;
    if (name == "normalized_fiber_length") return out_.norm_fiber_length;
    if (name == "normalized_fiber_velocity") return out_.norm_fiber_velocity;
    if (name == "active_force_length") return out_.active_force_length;
    if (name == "force_velocity") return out_.force_velocity;
    if (name == "passive_force_length") return out_.passive_force_length;
    if (name == "active_fiber_force") return out_.active_fiber_force;
    if (name == "passive_force") return out_.passive_force;
    if (name == "tension") return out_.tension;
    if (curves_ != Curves::kMujoco) {
      if (name == "pennation")
        return out_.pennation_cos < 0 ? kPi / 2 : std::acos(out_.pennation_cos);
      if (name == "tendon_length") return out_.tendon_length;
      if (name == "tendon_strain") return out_.tendon_strain;
    }
    throw std::out_of_range(Prefix() + "no quantity '" + name + "'");
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
    const double u = Clamp(excitation_, minimum, 1);
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
  RegisterKind("hill_muscle", std::move(specs), MakeHillMuscle);
}

}  // namespace caliper::actuators
