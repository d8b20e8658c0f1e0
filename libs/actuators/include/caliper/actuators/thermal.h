#pragma once
// The two-node thermal model of a DC motor as its datasheet gives it (maxon's "thermal data"):
// the winding and the housing, each a heat capacity, joined by the thermal resistances
// winding-housing and housing-ambient:
//   C_w dT_w/dt = P - (T_w - T_h) / R_wh
//   C_h dT_h/dt = (T_w - T_h) / R_wh - (T_h - T_a) / R_ha
// with C_w = tau_w / R_wh and C_h = tau_m / R_ha from the datasheet's time constants of the
// winding and of the motor. Engine-free; temperatures in degrees Celsius, SI otherwise.

namespace caliper::actuators {

/// A datasheet's thermal data. All four constants > 0 (Validate()).
struct ThermalParameters {
  double resistance_winding_housing = 0;  // R_wh [K/W]
  double resistance_housing_ambient = 0;  // R_ha [K/W]
  double time_constant_winding = 0;       // tau_w [s]
  double time_constant_motor = 0;         // tau_m [s]

  /// Throws std::invalid_argument naming the first constant that is not finite and > 0.
  void Validate() const;
  /// The heat capacities C_w = tau_w / R_wh and C_h = tau_m / R_ha [J/K].
  double winding_capacity() const { return time_constant_winding / resistance_winding_housing; }
  double housing_capacity() const { return time_constant_motor / resistance_housing_ambient; }
};

/// The linear system x' = A x + b P of the temperature rises x = (T_w - T_a, T_h - T_a),
/// advanced exactly over steps of dt with the power held: x(t + dt) = Phi x(t) + Gamma P, where
/// Phi = exp(A dt) and Gamma = A^-1 (Phi - I) b come from A's two real eigenvalues (A is similar
/// to a symmetric matrix) by Sylvester's formula, (exp(l dt) - 1) / l taken with expm1.
class TwoNodeThermal {
 public:
  /// Throws std::invalid_argument for constants out of range or a dt that is not > 0.
  void Configure(const ThermalParameters& parameters, double dt);
  double dt() const { return dt_; }

  /// Advances the rises (winding, housing) [K] by one step of dt at the power [W] into the
  /// winding, held through the step.
  void Step(double power, double* winding_rise, double* housing_rise) const {
    const double w = *winding_rise;
    const double h = *housing_rise;
    *winding_rise = phi_[0] * w + phi_[1] * h + gamma_[0] * power;
    *housing_rise = phi_[2] * w + phi_[3] * h + gamma_[1] * power;
  }

  /// The eigenvalues of A [1/s], fast (most negative) first: the exponentials of a step response.
  double fast_rate() const { return fast_; }
  double slow_rate() const { return slow_; }

 private:
  double dt_ = 0;
  double phi_[4] = {1, 0, 0, 1};  // row-major
  double gamma_[2] = {0, 0};      // [K/W]
  double fast_ = 0;
  double slow_ = 0;
};

/// The continuous current [A] that holds the winding at `max_winding` [degC] in ambient air at
/// `ambient` [degC] in the steady state, P = i^2 R(T) = (T - T_a) / (R_wh + R_ha), with the
/// winding's resistance at that temperature `hot_resistance` [ohm].
double ContinuousCurrent(const ThermalParameters& parameters, double max_winding, double ambient,
                         double hot_resistance);

}  // namespace caliper::actuators
