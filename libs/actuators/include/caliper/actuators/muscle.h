#pragma once
// Hill-type muscle models: the curves of OpenSim's Thelen2003Muscle and of MuJoCo's <muscle>
// actuator as free functions, and the parameter sets of the tendon actuator kind `hill_muscle`
// (muscle.cc). Normalised quantities: lengths by the optimal fibre length (Thelen) or by MuJoCo's
// L0, velocities by (optimal length * maximum contraction velocity), forces by the maximum
// isometric force. Thelen's sign convention: shortening velocity is negative.
//
// Kind `hill_muscle` (sgal::Actuator, command = excitation u in [0, 1], clamped):
//   options["curves"] = "thelen2003" (default) | "mujoco" | "millard2012"
//   options["tendon"] = "rigid" (default) | "elastic" (thelen2003, millard2012)
//   options["integrator"] = "exact" (default) | "mujoco" (rigid tendon, not millard2012): as
//                   MuJoCo's mj_step, the force from the activation at the start of the step at
//                   the path length at its start, then one explicit Euler step of the activation
//                   (so that MuJoCo models are reproduced step by step)
//   parameters: Thelen-, Mujoco- or MillardMuscleParameters by their snake_case names, plus
//   default_activation; a parameter of the other curve set is rejected.
// Step(path_length, path_speed, dt) lets the path move at path_speed during the step, advances
// the activation (and, with an elastic tendon, the fibre length) to the end of the step and
// returns the tension there, with the path at path_length + path_speed * dt. Tension only:
//   rigid tendon:   F0 (a fal fv + fpe) cos(pennation), fibre length and speed from the path;
//   elastic tendon: F0 fse(tendon strain), the fibre speed from the force balance through the
//                   inverse force-velocity curve (as OpenSim's Thelen2003Muscle);
//   mujoco:         F0 (a FL FV + FP) on MuJoCo's normalised length and speed;
//   millard2012:    F0 (a fal fv + fpe + beta v) cos along a rigid tendon; with an elastic one,
//                   F0 fse, the fibre velocity v solving fse = (a fal fv(v) + fpe + beta v) cos
//                   (Millard's damped equilibrium; beta = fiber_damping, 0 = undamped).
// Numerics: the activation ODE solved exactly over each step (the excitation held; closed form
// while falling, Halley's method on the implicit closed form while rising); the fibre length by a
// two-stage L-stable SDIRK (second order) in sub-steps of <= 1 ms, each stage solved by
// safeguarded Newton; Reset() puts the fibre at its zero-speed equilibrium.
// Quantities: the parameters (writable, validated), excitation, activation, fiber_length
// (writable with an elastic tendon), fiber_velocity, normalized_fiber_length,
// normalized_fiber_velocity, active_force_length, force_velocity, passive_force_length,
// active_fiber_force [N], passive_force [N] (millard2012: with the damping), tension [N];
// thelen2003 and millard2012 add pennation, tendon_length, tendon_strain; mujoco adds
// max_isometric_force and optimal_fiber_length (L0), read-only.

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

namespace caliper::actuators {

// ---------------------------------------------------------------------------------------------
// Thelen 2003 (OpenSim's Thelen2003Muscle)

/// Curve parameters of OpenSim's Thelen2003Muscle; the defaults are OpenSim's (the paper's
/// values are af 0.3, flen 1.8, fmax_tendon_strain 0.033).
struct ThelenCurveParameters {
  double kshape_active = 0.45;               // gamma of the active force-length Gaussian [-]
  double kshape_passive = 5.0;               // k_PE, passive force-length shape [-]
  double fmax_muscle_strain = 0.6;           // e0M: fibre strain where passive force = F0 [-]
  double fmax_tendon_strain = 0.04;          // e0T: tendon strain where tendon force = F0 [-]
  double af = 0.25;                          // A_f, force-velocity shape factor [-]
  double flen = 1.4;                         // F_len, maximum lengthening force / F0 [-]
  double fv_linear_extrap_threshold = 0.95;  // linear force-velocity beyond this * flen [-]
};

/// Active force-length multiplier exp(-(l - 1)^2 / gamma); l normalised fibre length.
double ThelenActiveForceLength(double norm_fiber_length, double kshape_active = 0.45);

/// Passive force-length (exp(k_PE (l - 1) / e0M) - 1) / (exp(k_PE) - 1) for l > 1, else 0.
double ThelenPassiveForceLength(double norm_fiber_length, double kshape_passive = 5.0,
                                double fmax_muscle_strain = 0.6);

/// Constants of Thelen's tendon curve for a strain e0T at F0, derived as OpenSim does: an
/// exponential toe F_toe (exp(k_toe e / e_toe) - 1) / (exp(k_toe) - 1) up to e_toe, then linear
/// k_lin (e - e_toe) + F_toe, continuous in value and slope and equal to 1 at e0T.
struct ThelenTendonConstants {
  double toe_strain = 0;        // e_toe = 99 e0T e^3 / (166 e^3 - 67) (0.6086 e0T) [-]
  double linear_stiffness = 0;  // k_lin = 0.67 / (e0T - e_toe) (42.80 for e0T = 0.04) [-]
  double toe_force = 0.33;      // F_toe [-]
  double toe_shape = 3.0;       // k_toe [-]
};
/// The constants for a tendon strain e0T [-] at F0.
ThelenTendonConstants ThelenTendonToe(double fmax_tendon_strain = 0.04);

/// Normalised tendon force at a tendon strain (length / slack length - 1); 0 when slack.
double ThelenTendonForceStrain(double strain, double fmax_tendon_strain = 0.04);
/// d(normalised tendon force)/d(strain).
double ThelenTendonStiffness(double strain, double fmax_tendon_strain = 0.04);

/// Force-velocity multiplier at a normalised fibre velocity (OpenSim's sign: shortening < 0) and
/// an activation: Thelen's eqs. 6-7 solved for the force, with the maximum shortening velocity
/// (0.25 + 0.75 a), linear below zero force and beyond fv_linear_extrap_threshold * flen. At
/// a = 1 and af = 0.25 the shortening branch is Hill's (1 + v) / (1 - 4 v).
double ThelenForceVelocity(double norm_fiber_velocity, double activation,
                           const ThelenCurveParameters& p = {});

/// The inverse: the normalised fibre velocity at which the force-velocity multiplier is fv
/// (OpenSim's calcdlceN with F = a fal fv), defined for every fv by the linear extrapolations.
double ThelenForceVelocityInverse(double force_velocity, double activation,
                                  const ThelenCurveParameters& p = {});
/// d(normalised velocity)/d(fv) of ThelenForceVelocityInverse.
double ThelenForceVelocityInverseSlope(double force_velocity, double activation,
                                       const ThelenCurveParameters& p = {});

/// First-order activation dynamics shared by OpenSim (Thelen, Millard) and MuJoCo:
/// da/dt = (u - a) / tau, tau = tau_act (0.5 + 1.5 a) when u > a, else tau_deact / (0.5 + 1.5 a);
/// u and a are clamped to [minimum_activation, 1] [1/s].
double ActivationRate(double excitation, double activation, double activation_time_constant,
                      double deactivation_time_constant, double minimum_activation = 0);

/// Constant-thickness (fixed-width parallelogram) pennation: the fibre length [m] of a muscle
/// whose fibres project `length_along_tendon` [m] on the tendon line, with height
/// optimal_fiber_length * sin(pennation_at_optimal); and the pennation angle [rad] of a fibre.
double PennatedFiberLength(double length_along_tendon, double optimal_fiber_length,
                           double pennation_at_optimal);
/// The pennation angle [rad] of a fibre of this length [m] (pi/2 when it is not longer than the
/// height, 0 without pennation).
double PennationAngle(double fiber_length, double optimal_fiber_length,
                      double pennation_at_optimal);

// ---------------------------------------------------------------------------------------------
// MuJoCo (engine_util_misc.c: mju_muscleGain, mju_muscleBias, mju_muscleDynamics)

/// Active force-length: half-quadratics through (lmin, 0), ((lmin+1)/2, 0.5), (1, 1),
/// ((1+lmax)/2, 0.5), (lmax, 0); 0 outside [lmin, lmax] (as upstream since 3.1.2; Debian's
/// 2.2.2 returns negative values below lmin).
double MujocoActiveForceLength(double norm_length, double lmin = 0.5, double lmax = 1.6);

/// Force-velocity at V = velocity / (L0 vmax): 0 for V <= -1, (V + 1)^2 up to 0,
/// fvmax - (y - V)^2 / y up to y = fvmax - 1, then fvmax.
double MujocoForceVelocity(double norm_velocity, double fvmax = 1.2);

/// Passive force: fpmax * 0.5 x^2 with x = (L - 1) / (b - 1) up to b = (1 + lmax) / 2, then
/// fpmax (0.5 + (L - b) / (b - 1)); 0 for L <= 1.
double MujocoPassiveForceLength(double norm_length, double lmax = 1.6, double fpmax = 1.3);

/// mju_muscleDynamics: ctrl clamped to [0, 1], the time constant from act clamped to [0, 1],
/// and (ctrl - act) / tau with act itself unclamped [1/s].
double MujocoActivationRate(double ctrl, double act, double tau_act = 0.01,
                            double tau_deact = 0.04);

/// L0 = (lengthrange_hi - lengthrange_lo) / (range1 - range0) [m]: the actuator length range is
/// mapped on the normalised range [range0, range1].
double MujocoOptimalLength(double lengthrange_lo, double lengthrange_hi, double range0 = 0.75,
                           double range1 = 1.05);
/// L = range0 + (length - lengthrange_lo) / L0 [-].
double MujocoNormalizedLength(double length, double lengthrange_lo, double lengthrange_hi,
                              double range0 = 0.75, double range1 = 1.05);

/// MuJoCo's force scale: `force` when it is >= 0, else scale / acc0 [N] (acc0 the norm of the
/// joint acceleration caused by a unit actuator force, computed by MuJoCo's compiler).
double MujocoForceScale(double force, double scale, double acc0);

// ---------------------------------------------------------------------------------------------
// Millard 2012 (OpenSim's Millard2012EquilibriumMuscle; Millard et al. 2013, J Biomech Eng
// 135(2)): every curve is a chain of C2-continuous quintic Bezier "corners", linear outside.

/// Curve parameters of OpenSim's ActiveForceLengthCurve, ForceVelocityCurve,
/// FiberForceLengthCurve and TendonForceLengthCurve; the defaults are OpenSim's. OpenSim derives
/// an unset stiffness from its strain (fibre 2 / strain, tendon 1.375 / strain): change both.
struct MillardCurveParameters {
  // active force-length, on the normalised fibre length [-]
  double min_norm_active_fiber_length = 0.4441;  // left shoulder (value minimum_value) [-]
  double transition_norm_fiber_length = 0.73;    // steep to shallow ascending limb [-]
  double max_norm_active_fiber_length = 1.8123;  // right shoulder (value minimum_value) [-]
  double shallow_ascending_slope = 0.8616;       // [-]
  double minimum_value = 0.1;                    // [-]
  // force-velocity, on the normalised fibre velocity (lengthening > 0, -1 at vmax) [-]
  double concentric_slope_at_vmax = 0;                   // [-]
  double concentric_slope_near_vmax = 0.25;              // at -0.9 [-]
  double isometric_slope = 5;                            // at 0 [-]
  double eccentric_slope_at_vmax = 0;                    // [-]
  double eccentric_slope_near_vmax = 0.15;               // at 0.9 [-]
  double max_eccentric_velocity_force_multiplier = 1.4;  // value at +1 [-]
  double concentric_curviness = 0.6;                     // 0 (sharp) .. 1 (round) [-]
  double eccentric_curviness = 0.9;                      // [-]
  // passive fibre force-length, on the fibre strain (normalised length - 1) [-]
  double fiber_strain_at_zero_force = 0;                 // [-]
  double fiber_strain_at_one_norm_force = 0.7;           // [-]
  double fiber_stiffness_at_low_force = 0.2;             // [-]
  double fiber_stiffness_at_one_norm_force = 2.0 / 0.7;  // [-]
  double fiber_curviness = 0.75;                         // [-]
  // tendon force-length, on the tendon strain (length / slack length - 1) [-]
  double tendon_strain_at_one_norm_force = 0.049;             // [-]
  double tendon_stiffness_at_one_norm_force = 1.375 / 0.049;  // [-]
  double tendon_norm_force_at_toe_end = 2.0 / 3.0;            // [-]
  double tendon_curviness = 0.5;                              // [-]
};

/// A curve y(x) made of quintic Bezier segments joined with equal value, slope and curvature,
/// extended by straight lines before the first and after the last segment. Evaluating at x
/// solves the segment's Bezier parameter: a cubic Hermite start from samples, one Halley step
/// (safeguarded Newton when the start was poor); values within ~2e-14 of the exact Bezier.
class MillardCurve {
 public:
  /// Control points of one segment (x increasing).
  struct Segment {
    std::array<double, 6> x{}, y{};
  };
  MillardCurve() = default;
  /// Throws std::invalid_argument when there is no segment or x does not increase.
  explicit MillardCurve(std::vector<Segment> segments);

  double Value(double x) const;
  double Slope(double x) const;             // dy/dx
  double SecondDerivative(double x) const;  // d2y/dx2
  /// Value and slope together (one parameter solve).
  std::pair<double, double> ValueAndSlope(double x) const;

  /// A root x of weight * y(x) + damping * x = target for a non-decreasing curve, weight and
  /// damping >= 0 (the damped force-velocity balance; weight 1, damping 0 is the inverse
  /// curve), with y and dy/dx there. NaN x when no x gives target (flat ends, damping 0).
  struct Solution {
    double x = 0, y = 0, slope = 0;
  };
  Solution SolveAffine(double weight, double damping, double target) const;
  /// The inverse x(y) of an increasing curve (NaN beyond a flat end).
  double Inverse(double y) const { return SolveAffine(1, 0, y).x; }

  double x_begin() const { return poly_.front().x[0]; }
  double x_end() const { return x_end_; }
  const std::vector<Segment>& segments() const { return segments_; }

 private:
  static constexpr int kSamples = 32;  // per segment, to start the parameter solve
  struct Poly {
    std::array<double, 6> x{}, y{};                 // power-basis coefficients in u
    std::array<double, kSamples + 1> xs{}, ys{};    // x, y at u = k / kSamples
    std::array<double, kSamples + 1> dxs{}, dys{};  // dx/du, dy/du there
  };
  // the parameter u in segment i where w y(u) + d x(u) = target (non-decreasing in u); kXOnly:
  // w = 0, d = 1 (x(u) = target) without evaluating y
  template <bool kXOnly>
  double SolveU(std::size_t i, double w, double d, double target) const;
  std::pair<std::size_t, double> Locate(double x) const;  // segment and its parameter u
  std::vector<Segment> segments_;
  std::vector<Poly> poly_;
  double x_end_ = 0, y_begin_ = 0, y_end_ = 0, slope_begin_ = 0, slope_end_ = 0;
};

/// One corner as OpenSim's SegmentedQuinticBezierToolkit builds it: from (x0, y0) with slope
/// dydx0 to (x1, y1) with slope dydx1, the inner control points pulled towards the lines'
/// intersection by 0.1 + 0.8 curviness. Throws std::invalid_argument unless the points and
/// slopes make a C-shaped corner (x1 > x0, the intersection nearer each end than they are).
MillardCurve::Segment MillardCorner(double x0, double y0, double dydx0, double x1, double y1,
                                    double dydx1, double curviness);

/// The four curves, each throwing std::invalid_argument naming the parameter out of range.
MillardCurve MillardActiveForceLengthCurve(const MillardCurveParameters& p = {});
MillardCurve MillardForceVelocityCurve(const MillardCurveParameters& p = {});
/// On the normalised fibre length (1 + strain).
MillardCurve MillardFiberForceLengthCurve(const MillardCurveParameters& p = {});
/// On the normalised tendon length (1 + strain).
MillardCurve MillardTendonForceLengthCurve(const MillardCurveParameters& p = {});

// ---------------------------------------------------------------------------------------------
// Parameter sets of the kind hill_muscle

/// options["curves"] = "thelen2003". Names in the actuator description are the field names.
struct ThelenMuscleParameters {
  double max_isometric_force = 1000;                    // F0 [N]
  double optimal_fiber_length = 0.1;                    // [m] (required in a description)
  double tendon_slack_length = 0.2;                     // [m] (required in a description)
  double pennation_angle = 0;                           // at optimal fibre length [rad], < maximum
  double max_contraction_velocity = 10;                 // [optimal fibre lengths / s]
  double activation_time_constant = 0.015;              // [s]
  double deactivation_time_constant = 0.050;            // [s]
  double minimum_activation = 0.01;                     // [-], > 0 with an elastic tendon
  double maximum_pennation_angle = 1.4706289056333368;  // acos(0.1) [rad]
  ThelenCurveParameters curves;  // by the field names of ThelenCurveParameters
};

/// options["curves"] = "mujoco": MuJoCo's gainprm/biasprm (range0, range1, force, scale, lmin,
/// lmax, vmax, fpmax, fvmax), the compiled actuator length range and acc0, dynprm (tau_act,
/// tau_deact). The tendon is rigid and unpennated; L is the normalised path length.
struct MujocoMuscleParameters {
  double range0 = 0.75;       // normalised length at lengthrange_lo [-]
  double range1 = 1.05;       // normalised length at lengthrange_hi [-]
  double force = -1;          // F0 [N]; < 0: scale / acc0
  double scale = 200;         // [(rad/s^2) or (m/s^2)], MuJoCo's force scale
  double acc0 = 0;            // [(rad/s^2)/N], needed when force < 0
  double lmin = 0.5;          // [-]
  double lmax = 1.6;          // [-]
  double vmax = 1.5;          // [L0/s]
  double fpmax = 1.3;         // passive scale: FP = fpmax / 2 at (1 + lmax) / 2 [-]
  double fvmax = 1.2;         // lengthening force limit [-]
  double lengthrange_lo = 0;  // [m] (required in a description)
  double lengthrange_hi = 0;  // [m] (required in a description)
  double tau_act = 0.01;      // [s]
  double tau_deact = 0.04;    // [s]
};

/// options["curves"] = "millard2012". Names in the actuator description are the field names.
struct MillardMuscleParameters {
  double max_isometric_force = 1000;                    // F0 [N]
  double optimal_fiber_length = 0.1;                    // [m] (required in a description)
  double tendon_slack_length = 0.2;                     // [m] (required in a description)
  double pennation_angle = 0;                           // at optimal fibre length [rad]
  double max_contraction_velocity = 10;                 // [optimal fibre lengths / s]
  double activation_time_constant = 0.010;              // [s]
  double deactivation_time_constant = 0.040;            // [s]
  double minimum_activation = 0.01;                     // [-]
  double maximum_pennation_angle = 1.4706289056333368;  // acos(0.1) [rad]
  double fiber_damping = 0.1;     // beta: F0 beta v / (vmax lopt) in the fibre [-]
  MillardCurveParameters curves;  // by the field names of MillardCurveParameters
};

/// Throws std::invalid_argument naming the first parameter out of range (and the one it
/// conflicts with).
void Validate(const ThelenMuscleParameters& p, bool elastic_tendon);
void Validate(const MujocoMuscleParameters& p);
/// Also builds the curves (their own checks); fiber_damping = 0 needs an invertible
/// force-velocity curve (slopes at vmax > 0), minimum_activation > 0 and minimum_value > 0.
void Validate(const MillardMuscleParameters& p, bool elastic_tendon);

/// The state-free part of the Millard muscle, curves built once: the forces of a fibre state.
/// Damped equilibrium (Millard 2013): F0 fse = F0 (a fal fv(v) + fpe + beta v) cos(pennation),
/// v the normalised fibre velocity; with an elastic tendon it gives v for a fibre length.
class MillardFiberModel {
 public:
  /// Forces and kinematics of one state.
  struct State {
    double fiber_length = 0;          // [m]
    double fiber_velocity = 0;        // [m/s]
    double norm_fiber_length = 0;     // [-]
    double norm_fiber_velocity = 0;   // [-]
    double cos_pennation = 1;         // [-]
    double tendon_length = 0;         // [m]
    double tendon_strain = 0;         // [-]
    double active_force_length = 0;   // fal [-]
    double force_velocity = 1;        // fv [-]
    double passive_force_length = 0;  // fpe [-]
    double active_fiber_force = 0;    // F0 a fal fv [N]
    double passive_force = 0;         // F0 (fpe + beta v), elastic and damping [N]
    double tendon_force = 0;          // F0 fse; the rigid tendon's is the fibres' along it [N]
    double tension = 0;               // [N], >= 0
  };

  /// p must be valid (Validate).
  explicit MillardFiberModel(const MillardMuscleParameters& p);

  const MillardMuscleParameters& parameters() const { return p_; }
  double height() const { return height_; }  // optimal_fiber_length sin(pennation_angle) [m]
  /// The shortest fibre: the longer of min_norm_active_fiber_length lopt and the height over
  /// sin(maximum_pennation_angle) [m].
  double minimum_fiber_length() const { return minimum_fiber_length_; }

  /// Rigid tendon: the fibres take the path minus the slack tendon, never shorter than
  /// minimum_fiber_length(); there and not lengthening (OpenSim's clamp): velocity 0, fv = 1,
  /// no fibre force (the tendon buckles, shorter than its slack length).
  State Rigid(double path_length, double path_speed, double activation) const;
  /// Elastic tendon, fibre length lm [m] (>= minimum_fiber_length()): velocity from the balance.
  State Elastic(double fiber_length, double path_length, double activation) const;
  /// The fibre velocity [m/s] of the balance at lm and its derivative by lm [1/s].
  std::pair<double, double> FiberVelocity(double fiber_length, double path_length,
                                          double activation) const;
  /// Isometric excess a fal + fpe - fse / cos [-] at lm, and its derivative by lm [1/m]: zero at
  /// the equilibrium of a fibre at rest.
  std::pair<double, double> IsometricExcess(double fiber_length, double path_length,
                                            double activation) const;

 private:
  struct Terms;
  Terms TermsAt(double lm, double path_length) const;
  MillardMuscleParameters p_;
  MillardCurve fal_, fv_, fpe_, fse_;
  double height_ = 0, minimum_fiber_length_ = 0;
};

}  // namespace caliper::actuators
