#pragma once
// What the Hill muscle parameter sets of `hill_muscle` (Thelen2003, Millard2012) require alike,
// in one place for muscle_parameters.cc and millard.cc. Private to libs/actuators.

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace caliper::actuators::muscle_detail {

/// The value as a message prints it.
inline std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Throws std::invalid_argument "parameter 'NAME' = VALUE: RULE" unless ok and finite.
inline void Require(bool ok, const std::string& name, double value, const std::string& rule) {
  if (!ok || !std::isfinite(value))
    throw std::invalid_argument("parameter '" + name + "' = " + Num(value) + ": " + rule);
}

/// The checks both parameter sets share: force, lengths, pennation, velocity, time constants.
template <class Parameters>
void RequireHillCommon(const Parameters& p, bool elastic_tendon) {
  constexpr double kPi = 3.14159265358979323846;
  Require(p.max_isometric_force >= 0, "max_isometric_force", p.max_isometric_force,
          "must be >= 0 N");
  Require(p.optimal_fiber_length > 0, "optimal_fiber_length", p.optimal_fiber_length,
          "must be > 0 m");
  if (elastic_tendon)
    Require(p.tendon_slack_length > 0, "tendon_slack_length", p.tendon_slack_length,
            "must be > 0 m with an elastic tendon");
  else
    Require(p.tendon_slack_length >= 0, "tendon_slack_length", p.tendon_slack_length,
            "must be >= 0 m");
  Require(p.maximum_pennation_angle > 0 && p.maximum_pennation_angle < kPi / 2,
          "maximum_pennation_angle", p.maximum_pennation_angle, "must be in (0, pi/2) rad");
  Require(p.pennation_angle >= 0 && p.pennation_angle < p.maximum_pennation_angle,
          "pennation_angle", p.pennation_angle,
          "must be in [0, maximum_pennation_angle = " + Num(p.maximum_pennation_angle) + ") rad");
  Require(p.max_contraction_velocity > 0, "max_contraction_velocity", p.max_contraction_velocity,
          "must be > 0 optimal fibre lengths/s");
  Require(p.activation_time_constant > 0, "activation_time_constant", p.activation_time_constant,
          "must be > 0 s");
  Require(p.deactivation_time_constant > 0, "deactivation_time_constant",
          p.deactivation_time_constant, "must be > 0 s");
}

}  // namespace caliper::actuators::muscle_detail
