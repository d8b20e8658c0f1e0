// The Hill muscle curves of muscle.h: Thelen 2003 (force-length, tendon, force-velocity and its
// inverse, activation, pennation) and MuJoCo's <muscle>. Millard 2012's are in millard.cc.

#include "muscle_curves.h"

#include <algorithm>
#include <cmath>

#include "caliper/actuators/muscle.h"

namespace caliper::actuators {

using muscle_detail::Clamp;
using muscle_detail::kMinVal;
using muscle_detail::kPi;
using muscle_detail::ThelenEccentricFactor;
using muscle_detail::ThelenSpeedLimit;

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
}  // namespace caliper::actuators
