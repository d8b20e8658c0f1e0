#pragma once
// What the curves (muscle_curves.cc) and the kind hill_muscle (muscle.cc) share: MuJoCo's smallest
// value, pi, a clamp and the shape of Thelen's force-velocity curve. Private to libs/actuators.

#include <algorithm>

#include "caliper/actuators/muscle.h"

namespace caliper::actuators::muscle_detail {

constexpr double kMinVal = 1e-15;  // MuJoCo's mjMINVAL
constexpr double kPi = 3.14159265358979323846;

inline double Clamp(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }

// shortening speed limit of Thelen's curve at activation a [normalised]
inline double ThelenSpeedLimit(double activation) { return 0.25 + 0.75 * Clamp(activation, 0, 1); }

inline double ThelenEccentricFactor(const ThelenCurveParameters& p) {
  return (2 + 2 / p.af) / (p.flen - 1);
}

}  // namespace caliper::actuators::muscle_detail
