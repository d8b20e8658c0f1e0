#pragma once
// A DC motor driving a spool through a gearbox, engine-free: the electrical and mechanical
// equations of TENDONS.md with the gearbox efficiency switching smoothly between driving and
// back-driven, so that a loaded gear holds while the motor pushes hard enough. Usable on its own
// (a load torque on the spool) or with a load that depends on the spool angle and speed (a
// tendon with a series-elastic element). SI units.

#include <array>
#include <cstddef>
#include <string>
#include <type_traits>

#include "caliper/actuators/actuator.h"
#include "caliper/actuators/thermal.h"

namespace caliper::actuators {

/// Motor, gearbox and spool constants. Defaults: the reference (ECCE) motor of TENDONS.md; the
/// spool radius is Roboy's, the only one given there.
struct DcMotorParameters {
  double resistance = 0.516;           // armature resistance R [ohm]
  double inductance = 5.73e-5;         // armature inductance L [H]
  double torque_constant = 11.5e-3;    // k_t [N m/A]
  double back_emf_constant = 11.5e-3;  // k_e [V s/rad]
  double rotor_inertia = 14.5e-7;      // J_rotor [kg m^2]
  double gear_inertia = 0.4e-7;        // J_gear, reflected to the motor shaft [kg m^2]
  double gear_ratio = 128;             // N: motor speed / spool speed [-]
  double efficiency = 0.59;            // eta: gearbox efficiency when the motor drives [-]
  double bridge_resistance = 0;        // R_bridge: H-bridge resistance in series [ohm]
  double current_limit = 0;            // |i| the driver allows [A]; 0: no limit
  double spool_radius = 0.0045;        // r_s [m]
  double max_substep = 1e-3;           // longest internal integration step [s] (see DcMotor:
                                       // refined to 1/3 ms after jumps); a step takes at most
                                       // kMaxSubstepsPerStep of them

  // Friction of the motor and the gearbox, lumped at the motor shaft (a datasheet's no-load
  // current i_0 gives a Coulomb friction of about k_t i_0):
  //   tau_f(W) = (tau_c + (tau_s - tau_c) exp(-(W / W_s)^2)) tanh(W / W_e) + b W,  W = N w
  // Coulomb with a Stribeck peak and viscous friction, made smooth through zero speed by the
  // tanh over W_e so that the implicit stages solve it like any other stiff term (a stuck motor
  // creeps at a speed of order W_e under a load below the breakaway torque).
  double coulomb_friction = 0;            // tau_c [N m]
  double static_friction = 0;             // tau_s, breakaway [N m]; 0: tau_c (no Stribeck peak)
  double stribeck_speed = 10;             // W_s [rad/s] at the motor shaft
  double viscous_friction = 0;            // b [N m s/rad] at the motor shaft
  double friction_smoothing_speed = 0.1;  // W_e [rad/s] at the motor shaft
  // Cogging: tau_cog = A sin(n N phi + psi), periodic in the rotor angle N phi.
  double cogging_amplitude = 0;  // A [N m]
  double cogging_count = 1;      // n, periods per rotor turn [-] (an integer >= 1)
  double cogging_phase = 0;      // psi [rad]
  // Heat (thermal.h): off while thermal_resistance_housing_ambient is 0; on, the other three
  // thermal constants must be > 0 too (a live edit sets R_ha last). The winding resistance follows
  // the copper's temperature, R (1 + alpha (T_w - T_ref)), the torque and back-EMF constants the
  // magnets' (the housing's), k (1 + beta (T_h - T_ref)); R and k_t above are the datasheet's
  // values at T_ref.
  double thermal_resistance_winding_housing = 0;       // R_wh [K/W]
  double thermal_resistance_housing_ambient = 0;       // R_ha [K/W]; 0: no thermal model
  double thermal_time_constant_winding = 0;            // tau_w [s]
  double thermal_time_constant_motor = 0;              // tau_m [s]
  double ambient_temperature = 25;                     // T_a [degC], also the temperatures at Reset
  double reference_temperature = 25;                   // T_ref [degC] of R and k_t
  double resistance_temperature_coefficient = 0.0039;  // alpha [1/K], copper
  double torque_constant_temperature_coefficient = 0;  // beta [1/K] (NdFeB about -0.001)
  // The driver's thermal protection (with the thermal model): from max - band up to max the
  // winding temperature lowers the current limit linearly to the continuous current that holds
  // the winding at max in the steady state (ContinuousCurrent()); above max it stays there.
  double max_winding_temperature = 125;  // [degC]; 0: no protection
  double derating_band = 10;             // [K]

  /// Throws std::invalid_argument naming the first parameter out of range (non-finite values,
  /// non-positive R, L, k_t, k_e, rotor inertia, N, r_s, max_substep, an efficiency outside
  /// (0, 1], negative gear inertia, bridge resistance, current limit, friction or cogging, a
  /// static friction below the Coulomb friction, a cogging count that is not a whole number
  /// >= 1, R_ha > 0 without the other thermal constants, a maximum winding temperature not above
  /// ambient).
  void Validate() const;
  /// Whether friction or cogging act.
  bool shaft_losses() const {
    return coulomb_friction > 0 || static_friction > 0 || viscous_friction > 0 ||
           cogging_amplitude > 0;
  }
  /// Whether the thermal model runs.
  bool thermal() const { return thermal_resistance_housing_ambient > 0; }
  ThermalParameters thermal_parameters() const {
    return {thermal_resistance_winding_housing, thermal_resistance_housing_ambient,
            thermal_time_constant_winding, thermal_time_constant_motor};
  }
};

/// The state of the motor and spool.
struct DcMotorState {
  double current = 0;               // armature current i [A]
  double spool_speed = 0;           // gearbox output speed w [rad/s], positive winds the line in
  double spool_angle = 0;           // phi [rad]
  double winding_temperature = 25;  // T_w [degC] (the ambient while there is no thermal model)
  double housing_temperature = 25;  // T_h [degC]
};

/// rho of TENDONS.md: the factor dividing the spool torque seen by the motor, eta when the motor
/// drives (i w > 0) and 1/eta when it is back-driven (i w < 0), blended by
/// eta + (1/eta - eta) (tanh(-500 i w - 5) + 1) / 2, evaluated as the equal logistic
/// eta + (1/eta - eta) / (1 + exp(1000 i w + 10)) (one exp; exactly eta or eta + (1/eta - eta)
/// where tanh is +-1 to the last bit).
double GearEfficiencyFactor(double efficiency, double current, double spool_speed);

/// The friction at the motor shaft of DcMotorParameters, its constants worked out once.
class ShaftFriction {
 public:
  ShaftFriction() = default;
  explicit ShaftFriction(const DcMotorParameters& parameters);
  /// tau_f(W) [N m] at the motor speed W [rad/s], and its derivative by W [N m s/rad] in *slope.
  double Torque(double motor_speed, double* slope) const;
  /// Whether Torque() is exactly affine between two motor speeds [rad/s]: viscous friction
  /// only, or both beyond the smoothing and the Stribeck peak on one side of zero, where Torque()
  /// takes tanh as +-1 and leaves the peak out.
  bool Affine(double speed0, double speed1) const;

 private:
  double viscous_ = 0;            // b [N m s/rad]
  double coulomb_ = 0;            // tau_c [N m]
  double peak_ = 0;               // tau_s - tau_c where positive [N m]
  double inverse_smoothing_ = 0;  // 1 / W_e [s/rad]
  double inverse_stribeck_ = 0;   // 1 / W_s [s/rad]
  double sign_speed_ = 0;         // beyond it tanh(W / W_e) is +-1 to the last bit [rad/s]
  double peak_speed_ = 0;         // beyond it exp(-(W / W_s)^2) < 3e-16 [rad/s]
  bool dry_ = false;              // Coulomb or static friction
};

/// A load on the spool that may depend on the spool's angle and speed and carry state of its own
/// (a series-elastic element). The motor solves for the end of each sub-step with the load
/// treated implicitly, so TorqueAt() is called several times per sub-step with trial values.
class SpoolLoad {
 public:
  virtual ~SpoolLoad() = default;
  /// The torque on the spool [N m], positive against positive spool speed, at the end of a
  /// stretch of h [s] from the last accepted sub-step that ends at this spool angle [rad] and
  /// speed [rad/s] (a load that moves with time takes it at that time: the motor calls Advance()
  /// for every sub-step in order). Must not change the load's state.
  virtual double TorqueAt(double spool_angle, double spool_speed, double h) const = 0;
  /// TorqueAt() on the line an implicit stage of the motor moves along, angle = spool_angle +
  /// angle_per_speed (w - spool_speed), for its Newton iteration: returns the torque at
  /// spool_speed and sets *slope to its derivative by w [N m s/rad] (one-sided at a kink) and
  /// [*low, *high] to changes of w [rad/s] (*low <= 0 <= *high) over which the torque is exactly
  /// affine with that slope (both 0 when not known). The default differentiates TorqueAt()
  /// numerically and knows no such range; loads that know better override it.
  virtual double TorqueAlong(double spool_angle, double spool_speed, double h,
                             double angle_per_speed, double* slope, double* low,
                             double* high) const;
  /// Accepts a sub-step of h [s] that ended at this spool angle [rad] and speed [rad/s].
  virtual void Advance(double spool_angle, double spool_speed, double h) = 0;
  /// The sign the torque never leaves: +1 never negative (a tendon), -1 never positive, 0
  /// either. Lets the motor rule out several solutions of an implicit stage cheaply.
  virtual int TorqueSign() const { return 0; }
};

/// A torque on the spool that does not depend on its motion.
class ConstantSpoolLoad : public SpoolLoad {
 public:
  /// torque [N m], positive against positive spool speed.
  explicit ConstantSpoolLoad(double torque) : torque_(torque) {}
  double TorqueAt(double, double, double) const override { return torque_; }
  double TorqueAlong(double, double, double, double, double* slope, double* low,
                     double* high) const override;
  void Advance(double, double, double) override {}
  int TorqueSign() const override { return torque_ > 0 ? 1 : (torque_ < 0 ? -1 : 0); }

 private:
  double torque_;  // [N m]
};

/// The motor + gearbox + spool model:
///   L di/dt = U - (R + R_bridge) i - k_e N w
///   N J dw/dt = k_t i - tau / (rho N),  J = J_rotor + J_gear,  tau the spool load torque
///   dphi/dt = w
/// Step() integrates these with sub-steps of at most max_substep by a two-stage L-stable
/// singly diagonally implicit Runge-Kutta method (second order); each stage is solved for the
/// spool speed with the load, the current and the efficiency switch implicit. Explicit methods
/// (RK4 at 1e-4 s) are not stable where a back-driven gear holds: the switch in rho makes the
/// speed equation stiff there (time constant of a few microseconds).
/// A sub-step longer than 1/3 ms is checked against the first-order result from its first
/// stage's slope: where they differ by more than 1e-3 rad/s (the current's difference counted as
/// the speed it would give over one electrical time constant, k_t L / (N J R) per ampere) it is
/// redone as sub-steps of at most 1/3 ms (and at least dt / kMaxSubstepsPerStep, so that a step
/// never costs more than twice kMaxSubstepsPerStep sub-steps). That happens just after a jump in
/// the voltage or the load; elsewhere the motion is smooth and long sub-steps are as accurate.
/// The load sees only accepted sub-steps (Advance()), so a refused one leaves no trace.
/// The default max_substep, 1 ms (one sub-step per smooth 1 ms step), keeps the speed within
/// 1.4e-4 rad/s of a 10 us reference at the sampled times of the CALIPER-era scenario (0.7 % of
/// its steps refined; 2.4e-3 rad/s without the check), as 1/3 ms sub-steps throughout do (1.3e-5
/// with 0.1 ms ones, at about 3.5 times their cost); up to about 1/3 ms (three electrical time
/// constants) the current follows voltage steps to a few mA. The cost is that of the stages,
/// each one Newton step on a serial chain of dependent operations (about 25 ns here): per 1 ms
/// step about 90 ns with the default, 230 ns with 1/3 ms sub-steps throughout.
/// A load that depends on time (the dc_motor_tendon kind's: its path moves through the step) is
/// evaluated at each stage's own time, h after the last accepted sub-step, so that the whole
/// stays second order in the step.
/// A stage (the current and the angle are linear in the speed) is solved by Newton's method with
/// its analytic derivative from an extrapolation of the last stage, kept inside the bracket its
/// residuals give. It stops after the first step whose result provably lies within 1.5e-12 of the
/// speed scale |w| + 1 V / (k_e N) (0.68 rad/s for the reference motor) of the solution: the
/// residual there is bounded from the load's tangent (and its affine range, or one more load
/// evaluation) and the switch's derivatives, |d^n(1/rho)/dx^n| <= |d(1/rho)/dx|. Where a stage
/// may have several solutions (a current against the load while the speed crosses zero) the
/// solution must be the first from the stage's base speed, or the stage falls back to the
/// bracketing search from there and TOMS 748 (Boost.Math; as it does should Newton fail).
/// With a current limit the driver lowers the voltage so that |i| stays at the limit.
/// Friction and cogging (DcMotorParameters) enter the speed equation at the motor shaft,
///   N J dw/dt = k_t i - tau / (rho N) - tau_f(N w) - tau_cog(N phi),
/// implicit in each stage like the load; where their falling parts (the Stribeck peak, cogging)
/// could give a stage several solutions, the bracketing search picks the first from the base.
/// With the thermal model a step uses the resistance and constants at the temperatures of its
/// middle (extrapolated from the last step's change), then advances the temperatures exactly
/// (TwoNodeThermal) on the Joule power in the winding over the step, R(T) times the mean of i^2
/// (trapezoidal over the sub-steps); the driver's thermal protection sets the current limit at
/// the start of each step from the winding's temperature.
class DcMotor {
 public:
  /// Throws std::invalid_argument when the parameters are out of range.
  explicit DcMotor(const DcMotorParameters& parameters = {});

  const DcMotorParameters& parameters() const { return parameters_; }
  /// Replaces the parameters (the state is kept). Throws std::invalid_argument (see Validate).
  void set_parameters(const DcMotorParameters& parameters);

  const DcMotorState& state() const { return state_; }
  void set_state(const DcMotorState& state) {
    state_ = state;
    last_acceleration_ = 0;
  }
  /// Zero current, speed and angle.
  void Reset();

  /// A locked spool (held fixed, speed zero) or a free one.
  void set_locked(bool locked);
  bool locked() const { return locked_; }

  /// Advances by dt [s] > 0 with the terminal voltage [V] held and the spool loaded by `load`.
  /// Throws std::invalid_argument (the state unchanged) for a non-finite voltage, a dt that is
  /// not positive, or one that would take more than kMaxSubstepsPerStep sub-steps.
  void Step(double voltage, double dt, SpoolLoad& load);
  /// Advances by dt [s] with a constant load torque [N m] (positive against positive speed).
  void Step(double voltage, double dt, double load_torque);

  /// The sub-steps a step of dt [s] takes with this max_substep [s] (as a double: it may be
  /// beyond any int).
  static double Substeps(double dt, double max_substep);
  /// Throws std::invalid_argument when a step of dt [s] would take more than
  /// kMaxSubstepsPerStep sub-steps of at most max_substep [s]; the message gives the smallest
  /// max_substep and the longest time step allowed.
  static void CheckSubsteps(double dt, double max_substep);

  /// Writes everything Step() changes (kStateSize values: the state, the applied voltage and
  /// load torque, the Newton start value's memory, the exp() and sin() caches, the
  /// temperatures' last change, and what they made of the resistance, the constants and the
  /// driver's limit, which the readouts show) for RestoreState(), after which a repeated Step()
  /// gives the same result bit for bit.
  void SaveState(double* out) const {
    const auto fields = StateFields(*this);
    for (std::size_t i = 0; i < kStateSize; ++i) out[i] = *fields[i];
  }
  /// Reads back the kStateSize values SaveState() wrote.
  void RestoreState(const double* in) {
    const auto fields = StateFields(*this);
    for (std::size_t i = 0; i < kStateSize; ++i) *fields[i] = in[i];
  }
  static constexpr std::size_t kStateSize = 20;

 private:
  // what SaveState() writes and RestoreState() reads, in their order (double* or const double*)
  template <typename Motor>
  using StateField = std::conditional_t<std::is_const_v<Motor>, const double*, double*>;
  template <typename Motor>
  static std::array<StateField<Motor>, kStateSize> StateFields(Motor& m) {
    return {&m.state_.current,
            &m.state_.spool_speed,
            &m.state_.spool_angle,
            &m.applied_voltage_,
            &m.load_torque_,
            &m.last_acceleration_,
            &m.exp_argument_,
            &m.exp_value_,
            &m.state_.winding_temperature,
            &m.state_.housing_temperature,
            &m.winding_change_,
            &m.housing_change_,
            &m.sin_argument_,
            &m.sin_value_,
            &m.cos_value_,
            &m.effective_.resistance,
            &m.effective_.torque_constant,
            &m.effective_.back_emf_constant,
            &m.effective_.current_limit,
            &m.derating_};
  }

 public:
  /// The voltage the driver applied at the end of the last step [V] (lower than the command
  /// while the current is limited).
  double applied_voltage() const { return applied_voltage_; }
  /// The spool load torque at the end of the last step [N m].
  double load_torque() const { return load_torque_; }
  /// Motor shaft speed N w [rad/s].
  double motor_speed() const { return parameters_.gear_ratio * state_.spool_speed; }
  /// Electrical input power U i [W].
  double electrical_power() const { return applied_voltage_ * state_.current; }
  /// The total inertia J_rotor + J_gear at the motor shaft [kg m^2].
  double inertia() const { return parameters_.rotor_inertia + parameters_.gear_inertia; }
  /// The resistance, torque constant and current limit of the last step (at its temperatures;
  /// the parameters' without the thermal model) [ohm], [N m/A], [A] (0: none).
  double hot_resistance() const { return effective_.resistance; }
  double hot_torque_constant() const { return effective_.torque_constant; }
  double current_limit() const { return effective_.current_limit; }
  /// The motor torque k_t i at the end of the last step [N m].
  double motor_torque() const { return effective_.torque_constant * state_.current; }
  /// Friction and cogging torques at the motor shaft at the end of the last step [N m].
  double friction_torque() const;
  double cogging_torque() const;
  /// How far the thermal protection has lowered the current limit in the last step: 0 not at
  /// all, 1 down to the continuous current.
  double derating() const { return derating_; }
  /// The continuous current at the maximum winding temperature [A] (0 without protection).
  double continuous_current() const;

 private:
  // the sub-steps of a step of dt and the constants of their implicit stages (all stages share
  // c = gamma h)
  struct StageConstants {
    double dt = 0;                   // step [s]; 0: to be computed
    int substeps = 1;                // per step
    double h = 0;                    // sub-step [s]
    double c = 0;                    // gamma h [s]
    double inverse_c = 0;            // [1/s]
    double second_base = 0;          // (1 - gamma) / gamma [-]
    double current_base = 0;         // d(current)/d(base current) [-]
    double current_drive = 0;        // d(current)/d(voltage) [A/V]
    double current_slope = 0;        // d(current)/d(speed) [A s/rad]
    double c_torque = 0;             // C k_t, C = c / (N J) [rad/(s A)]
    double c_ratio = 0;              // C / N [s/(kg m^2)]
    double spread = 0;               // 1/eta - eta [-]
    double inverse_rho_driving = 0;  // 1 / eta [-]
    double inverse_rho_driven = 0;   // 1 / (eta + 1/eta - eta) [-]
    double tolerance = 0;            // of the stage speeds at w = 0 [rad/s]
    double current_to_speed = 0;     // k_t L / (N J R): a current error as a speed [rad/(s A)]
    double c_shaft = 0;              // C = c / (N J) [rad/(s N m)]
    double c_over_inductance = 0;    // c / L [s/H]
    double cogging_per_angle = 0;    // n N: cogging radians per spool radian [-]
    double cogging_slope = 0;        // A n N c: d(tau_cog)/dw over cos [N m s/rad]
    double cogging_curvature = 0;    // A (n N c)^2 / 2: bound of the remainder [N m s^2/rad^2]
    double shaft_falling = 0;        // C times the most the shaft torque can fall per rad/s [-]
  };
  struct Stage {
    double current = 0;      // [A]
    double spool_speed = 0;  // [rad/s]
    double spool_angle = 0;  // [rad]
    double voltage = 0;      // applied [V]
  };
  void UpdateConstants(double dt);
  // the constants that depend on the resistance and the motor constants (effective_)
  void Retune(StageConstants* constants) const;
  // sin(x) and cos(x), from the last exact values while x moves little
  void SinCos(double x, double* sine, double* cosine) const;
  StageConstants ConstantsFor(double dt, double max_substep) const;
  // exp(x), from the last exact value while x moves little
  double Exp(double x) const;
  // the stage at spool speed w from the base a (current limited, voltage lowered)
  Stage StageAt(const DcMotorState& a, double voltage, double w) const;
  // one implicit stage's residual and the checks of SolveStage's Newton steps (dc_motor.cc)
  class StageEquation;
  // Solves w = a.w + c f(w) for one implicit stage whose end lies h_load after the last
  // sub-step, starting from the guess w0.
  double SolveStage(const DcMotorState& a, double voltage, double h_load, double w0,
                    const SpoolLoad& load) const;
  // the original bracketing + TOMS 748 solution (fallback)
  double SolveStageBracketing(const DcMotorState& a, double voltage, double h_load,
                              const SpoolLoad& load) const;
  // One sub-step; with check, refused (false, nothing changed) when its error estimate is
  // too large.
  bool Substep(double voltage, SpoolLoad& load, bool last, bool check);

  // the shaft's friction and cogging torque [N m] at spool speed w [rad/s] and spool angle phi
  // [rad], and its derivative along a stage (phi moving by c per rad/s of w) by w
  // with the stage constants k: also friction alone and its derivative by w
  double ShaftTorque(const StageConstants& k, double w, double phi, double* d_torque,
                     double* friction, double* d_friction) const;
  // the winding's resistance at a temperature [degC], kept positive however cold (the
  // coefficient is a linear fit near room temperature) [ohm]
  double ResistanceAt(double winding) const;
  // effective_ and derating_ from the temperatures: the resistance and constants at the
  // middle of a step (extrapolated from the last step's change), the driver's limit from the
  // winding's temperature at its start, for a step at this voltage [V]
  void UpdateEffective(double voltage);
  // the temperatures' effect at the start of a step (thermal model on)
  void BeginThermalStep(double voltage, double dt);
  void EndThermalStep(double dt);

  DcMotorParameters parameters_;
  DcMotorParameters effective_;           // parameters_ at the step's temperatures and derating
  bool shaft_ = false;                    // parameters_.shaft_losses()
  bool friction_ = false;                 // any friction
  ShaftFriction friction_constants_;      // parameters_'s
  double continuous_ = 0;                 // continuous_current() [A]
  bool thermal_ = false;                  // parameters_.thermal()
  TwoNodeThermal thermal_model_;          // for steps of thermal_model_.dt()
  double joule_ = 0;                      // integral of i^2 over the step so far [A^2 s]
  double winding_change_ = 0;             // in the last step [K]
  double housing_change_ = 0;             // [K]
  double derating_ = 0;                   // [-]
  double constants_resistance_ = 0;       // effective_'s when constants_ were last tuned [ohm]
  double constants_torque_constant_ = 0;  // [N m/A]
  bool fine_stale_ = false;               // fine_ still to be retuned
  mutable double sin_argument_ = 0;       // the last exact sin() and cos(): argument [rad]
  mutable double sin_value_ = 0;          // and values
  mutable double cos_value_ = 1;
  DcMotorState state_;
  bool locked_ = false;
  double applied_voltage_ = 0;       // [V]
  double load_torque_ = 0;           // [N m]
  StageConstants constants_;         // for steps of constants_.dt (recomputed when dt changes)
  StageConstants fine_;              // for a refused sub-step of constants_.h redone shorter
  bool refine_ = false;              // sub-steps are checked (longer than the refined ones)
  double last_acceleration_ = 0;     // dw/dt at the end of the last sub-step [rad/s^2], a guess
  int load_sign_ = 0;                // the load's TorqueSign() in this step
  mutable double exp_argument_ = 0;  // the last exact exp(): argument [-]
  mutable double exp_value_ = 1;     // and value [-]
};

}  // namespace caliper::actuators
