// Heat, friction, cogging and the driver (PWM, slew, command delay) of the DC motor against
// closed forms computed here independently of the model's own formulas: the thermal step
// response from an eigen-decomposition (Eigen) of the two-node system, a hot run with the
// resistance fed back, the no-load speed with friction, Coulomb stick-slip of a rotor pulled
// through a spring, a rotor swinging in a cogging well as a pendulum (complete elliptic
// integral), and a delayed PD loop against the same loop with its commands shifted by hand.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <boost/math/special_functions/ellint_1.hpp>
#include <cmath>
#include <deque>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/actuators/actuator.h"
#include "caliper/actuators/dc_motor.h"
#include "caliper/actuators/thermal.h"
#include "caliper/sgal/scene.h"

namespace caliper::actuators {
namespace {

constexpr double kPi = 3.14159265358979323846;

// thermal data of the kind a maxon datasheet gives (a motor of about 150 W)
ThermalParameters Datasheet() {
  ThermalParameters t;
  t.resistance_winding_housing = 1.6;   // [K/W]
  t.resistance_housing_ambient = 4.65;  // [K/W]
  t.time_constant_winding = 41.6;       // [s]
  t.time_constant_motor = 1120;         // [s]
  return t;
}

// the rises x = (T_w - T_a, T_h - T_a) of x' = A x + b P from x(0) = 0 at time t, by Eigen's
// eigen-decomposition of A: x(t) = x_ss - V exp(L t) V^-1 x_ss, x_ss = -A^-1 b P; `feedback`
// [W/K] adds a power proportional to the winding's rise (the resistance's temperature)
Eigen::Vector2d ClosedForm(const ThermalParameters& t, double power, double feedback, double time) {
  const double cw = t.time_constant_winding / t.resistance_winding_housing;
  const double ch = t.time_constant_motor / t.resistance_housing_ambient;
  const double gwh = 1 / t.resistance_winding_housing;
  const double gha = 1 / t.resistance_housing_ambient;
  Eigen::Matrix2d a;
  a << (-gwh + feedback) / cw, gwh / cw, gwh / ch, -(gwh + gha) / ch;
  const Eigen::Vector2d b(power / cw, 0);
  const Eigen::Vector2d steady = -a.fullPivLu().solve(b);
  Eigen::EigenSolver<Eigen::Matrix2d> solver(a);
  const Eigen::Matrix2d v = solver.eigenvectors().real();
  const Eigen::Vector2d l = solver.eigenvalues().real();
  const Eigen::Vector2d c = v.fullPivLu().solve(steady);
  Eigen::Vector2d decay;
  decay << std::exp(l(0) * time) * c(0), std::exp(l(1) * time) * c(1);
  return steady - v * decay;
}

TEST(Thermal, StepResponseIsTheTwoExponentialsTo1e9) {
  const ThermalParameters t = Datasheet();
  TwoNodeThermal model;
  const double dt = 1e-3;
  model.Configure(t, dt);
  const double power = 20;  // [W]
  double w = 0;
  double h = 0;
  double worst = 0;
  const long steps = 3000000;  // 3000 s: nearly three motor time constants
  for (long i = 1; i <= steps; ++i) {
    model.Step(power, &w, &h);
    if (i % 1000 == 0) {
      const Eigen::Vector2d exact = ClosedForm(t, power, 0, i * dt);
      worst = std::max({worst, std::abs(w - exact(0)), std::abs(h - exact(1))});
    }
  }
  const Eigen::Vector2d steady = ClosedForm(t, power, 0, 1e9);
  // the steady rise is P (R_wh + R_ha) at the winding, P R_ha at the housing
  EXPECT_NEAR(steady(0), power * (1.6 + 4.65), 1e-9);
  EXPECT_NEAR(steady(1), power * 4.65, 1e-9);
  // relative to the steady rise
  EXPECT_LT(worst / steady(0), 1e-10) << "worst " << worst << " K";
  std::printf("thermal step: worst error %.3g K over 3000 s (steady rise %.2f K)\n", worst,
              steady(0));
}

DcMotorParameters HotMotor() {
  DcMotorParameters p;  // the reference motor
  const ThermalParameters t = Datasheet();
  p.thermal_resistance_winding_housing = t.resistance_winding_housing;
  p.thermal_resistance_housing_ambient = t.resistance_housing_ambient;
  p.thermal_time_constant_winding = t.time_constant_winding;
  p.thermal_time_constant_motor = t.time_constant_motor;
  p.ambient_temperature = 25;
  p.reference_temperature = 25;
  return p;
}

// a locked motor already carrying `current` [A], steady (L di/dt = 0 from the first step)
void LockAtCurrent(DcMotor* motor, double current) {
  motor->set_locked(true);
  DcMotorState s = motor->state();
  s.current = current;
  motor->set_state(s);
}

TEST(Thermal, LockedMotorAtConstantVoltageHeatsAsTheClosedForm) {
  // no temperature coefficient: the power U^2 / R is constant
  DcMotorParameters p = HotMotor();
  p.resistance_temperature_coefficient = 0;
  p.max_winding_temperature = 0;
  DcMotor motor(p);
  const double voltage = 1.5;
  LockAtCurrent(&motor, voltage / p.resistance);
  const double dt = 1e-3;
  const double power = voltage * voltage / p.resistance;
  double worst = 0;
  for (long i = 1; i <= 200000; ++i) {
    motor.Step(voltage, dt, 0.0);
    if (i % 500 == 0) {
      const Eigen::Vector2d exact = ClosedForm(Datasheet(), power, 0, i * dt);
      worst = std::max({worst, std::abs(motor.state().winding_temperature - 25 - exact(0)),
                        std::abs(motor.state().housing_temperature - 25 - exact(1))});
    }
  }
  EXPECT_LT(worst, 1e-9) << worst;  // [K]
  std::printf("locked motor at %.2f W: worst error %.3g K over 200 s\n", power, worst);
}

TEST(Thermal, HotRunDriftsResistanceAndTorqueConstantAsTheAnalyticRun) {
  // a current-limited locked motor: i^2 = I^2 held, P = I^2 R0 (1 + alpha (T_w - T_ref)) is
  // linear in the winding's rise, so the run is again a linear system (ClosedForm's feedback)
  DcMotorParameters p = HotMotor();
  p.max_winding_temperature = 0;
  p.current_limit = 7;
  p.torque_constant_temperature_coefficient = -0.0011;
  DcMotor motor(p);
  LockAtCurrent(&motor, p.current_limit);
  const double dt = 1e-3;
  const double i2r = p.current_limit * p.current_limit * p.resistance;  // [W] at T_ref
  const double alpha = p.resistance_temperature_coefficient;
  double worst_t = 0;
  double worst_r = 0;
  double worst_k = 0;
  for (long i = 1; i <= 600000; ++i) {
    motor.Step(24, dt, 0.0);
    if (i % 1000 != 0) continue;
    const Eigen::Vector2d end = ClosedForm(Datasheet(), i2r, i2r * alpha, i * dt);
    // a step's resistance and constants are those of its middle
    const Eigen::Vector2d mid = ClosedForm(Datasheet(), i2r, i2r * alpha, (i - 0.5) * dt);
    worst_t = std::max(worst_t, std::abs(motor.state().winding_temperature - 25 - end(0)));
    const double r = p.resistance * (1 + alpha * mid(0));
    const double k = p.torque_constant * (1 - 0.0011 * mid(1));
    worst_r = std::max(worst_r, std::abs(motor.hot_resistance() - r) / r);
    worst_k = std::max(worst_k, std::abs(motor.hot_torque_constant() - k) / k);
    // the driver's voltage holds the current against the hot resistance
    ASSERT_NEAR(motor.applied_voltage(), r * p.current_limit, 1e-6 * r * p.current_limit);
    ASSERT_NEAR(motor.motor_torque(), k * p.current_limit, 1e-6 * k * p.current_limit);
  }
  const double final_rise = motor.state().winding_temperature - 25;
  EXPECT_GT(final_rise, 100);           // hot: the resistance grew by 40 %
  EXPECT_LT(worst_t, 1e-8) << worst_t;  // [K]
  EXPECT_LT(worst_r, 1e-10) << worst_r;
  EXPECT_LT(worst_k, 1e-10) << worst_k;
  std::printf(
      "hot run 600 s at 7 A: winding +%.2f K, worst %.3g K; R %.4f -> %.4f ohm "
      "(worst rel. %.2g), k_t worst rel. %.2g\n",
      final_rise, worst_t, p.resistance, motor.hot_resistance(), worst_r, worst_k);
}

TEST(Thermal, DriverDeratesToTheSteadyStateOfItsPolicy) {
  DcMotorParameters p = HotMotor();
  p.max_winding_temperature = 125;
  p.derating_band = 10;
  DcMotor motor(p);
  motor.set_locked(true);
  const double continuous = motor.continuous_current();
  // (125 - 25) K over (R_wh + R_ha) at the hot resistance
  const double hot = p.resistance * (1 + 0.0039 * 100);
  EXPECT_NEAR(continuous, std::sqrt(100 / (6.25 * hot)), 1e-12);
  // the policy's steady state: below the maximum the limit is above the continuous current and
  // the winding warms; at it the limit is the continuous current, which holds it there. So the
  // winding approaches the maximum from below, the current the continuous current from above.
  double highest = 0;
  double first_derating = -1;
  for (long i = 1; i <= 8000000; ++i) {  // 8000 s: seven of the housing's time constants
    motor.Step(6, 1e-3, 0.0);            // a stall current of 11.6 A: 69 W
    highest = std::max(highest, motor.state().winding_temperature);
    if (first_derating < 0 && motor.derating() > 0) first_derating = i * 1e-3;
  }
  EXPECT_GT(first_derating, 0);
  EXPECT_LT(highest, 125.0) << "the winding passed its maximum";
  const double winding = motor.state().winding_temperature;
  EXPECT_NEAR(winding, 125.0, 1e-4);  // [degC]
  EXPECT_NEAR(std::abs(motor.state().current), continuous, 1e-5 * continuous);
  std::printf(
      "derating from %.1f s; after 8000 s the winding %.3g K below its maximum, the current "
      "%.3g A above the continuous %.4f A\n",
      first_derating, 125.0 - winding, std::abs(motor.state().current) - continuous, continuous);
}

// a hot motor: the winding at `winding` [degC], the housing 40 K cooler
DcMotor HotAt(DcMotorParameters p, double winding) {
  DcMotor motor(p);
  DcMotorState s = motor.state();
  s.winding_temperature = winding;
  s.housing_temperature = winding - 40;
  motor.set_state(s);
  return motor;
}

TEST(Thermal, ADriverWithoutALimitOfItsOwnDeratesAtAnyVoltage) {
  // at the maximum the limit is the continuous current, also at a voltage whose stall current
  // is below it and for a motor the load back-drives
  DcMotorParameters p = HotMotor();
  DcMotor motor = HotAt(p, 126);
  const double continuous = motor.continuous_current();
  motor.Step(0.5, 1e-3, 0.0);
  EXPECT_EQ(motor.derating(), 1);
  EXPECT_EQ(motor.current_limit(), continuous);
  // 15 N m at the spool back-drives the motor: the back-EMF's current is held too
  for (int i = 0; i < 200; ++i) motor.Step(0, 1e-3, -15);
  EXPECT_GT(motor.state().spool_speed, 0);
  EXPECT_LE(std::abs(motor.state().current), continuous * (1 + 1e-12));
  EXPECT_GT(std::abs(motor.state().current), 0.5 * continuous);
}

TEST(Thermal, ANegativeCoefficientKeepsTheProtectionOn) {
  DcMotorParameters p = HotMotor();
  p.resistance_temperature_coefficient = -0.02;  // R(125 degC) would be negative unclamped
  DcMotor motor = HotAt(p, 126);
  EXPECT_GT(motor.continuous_current(), 0);
  motor.Step(6, 1e-3, 0.0);
  EXPECT_GT(motor.current_limit(), 0);
  EXPECT_LE(std::abs(motor.state().current), motor.current_limit() * (1 + 1e-12));
}

TEST(Thermal, TurnedOffTheMotorReadsTheAmbientAndARestoreReadsHot) {
  DcMotorParameters p = HotMotor();
  DcMotor motor = HotAt(p, 100);
  motor.Step(3, 1e-3, 0.0);
  const double hot = motor.hot_resistance();
  EXPECT_GT(hot, p.resistance * 1.2);
  // what the readouts show comes back with the state
  double saved[DcMotor::kStateSize];
  motor.SaveState(saved);
  DcMotor other(p);
  other.RestoreState(saved);
  EXPECT_EQ(other.hot_resistance(), hot);
  EXPECT_EQ(other.hot_torque_constant(), motor.hot_torque_constant());
  EXPECT_EQ(other.current_limit(), motor.current_limit());
  // a live edit keeps a hot motor hot (at the temperatures of the coming step's middle);
  // turning the model off reads the ambient
  p.derating_band = 12;
  motor.set_parameters(p);
  EXPECT_NEAR(motor.hot_resistance(), hot, 1e-4 * hot);
  p.thermal_resistance_housing_ambient = 0;
  motor.set_parameters(p);
  EXPECT_EQ(motor.state().winding_temperature, p.ambient_temperature);
  EXPECT_EQ(motor.hot_resistance(), p.resistance);
}

TEST(Friction, NoLoadSpeedBalancesCoulombAndViscousFriction) {
  DcMotorParameters p;
  p.coulomb_friction = 2e-3;  // [N m]
  p.static_friction = 3e-3;   // its Stribeck peak is far below the speed reached
  p.stribeck_speed = 5;       // [rad/s]
  p.viscous_friction = 2e-6;  // [N m s/rad]
  DcMotor motor(p);
  const double u = 6;
  for (int i = 0; i < 3000; ++i) motor.Step(u, 1e-3, 0.0);
  // U = R i + k_e W, k_t i = tau_c + b W (unloaded: the efficiency does not enter)
  const double r = p.resistance;
  const double w = (p.torque_constant * u / r - p.coulomb_friction) /
                   (p.torque_constant * p.back_emf_constant / r + p.viscous_friction);
  EXPECT_NEAR(motor.motor_speed(), w, 1e-12 * w);
  EXPECT_NEAR(motor.friction_torque(), p.coulomb_friction + p.viscous_friction * w, 1e-12);
  EXPECT_NEAR(motor.state().current, (u - p.back_emf_constant * w) / r, 1e-9);
  std::printf("no-load speed with friction: %.6f rad/s, closed form %.6f (relative error %.2g)\n",
              motor.motor_speed(), w, std::abs(motor.motor_speed() - w) / w);
}

// a bare rotor: no gear, no losses in it, the winding practically open (no electrical damping)
DcMotorParameters BareRotor(double inertia) {
  DcMotorParameters p;
  p.gear_ratio = 1;
  p.efficiency = 1;
  p.rotor_inertia = inertia;  // [kg m^2]
  p.gear_inertia = 0;
  p.resistance = 1e6;
  return p;
}

TEST(Friction, StuckBelowTheBreakawayTorque) {
  const DcMotorParameters defaults;
  DcMotorParameters p = BareRotor(defaults.rotor_inertia + defaults.gear_inertia);
  p.coulomb_friction = 0.01;
  p.static_friction = 0.02;
  p.stribeck_speed = 0.2;
  p.friction_smoothing_speed = 1e-3;
  DcMotor motor(p);
  // 0.015 N m, between the Coulomb and the breakaway torque, pushes on a motor at rest
  for (int i = 0; i < 2000; ++i) motor.Step(0, 1e-3, -0.015);
  EXPECT_LT(std::abs(motor.motor_speed()), 2e-3);  // creeping at the order of W_e
  EXPECT_NEAR(motor.friction_torque(), 0.015, 1e-5);
  // above the breakaway it runs away
  for (int i = 0; i < 100; ++i) motor.Step(0, 1e-3, -0.025);
  EXPECT_GT(motor.motor_speed(), 0.5);
}

// a spring from the spool to a point that turns at a constant speed (a block on a belt: the
// belt's end of the spring moves, friction holds the block to the ground)
class DraggedSpring : public SpoolLoad {
 public:
  DraggedSpring(double stiffness, double speed) : k_(stiffness), speed_(speed) {}
  double TorqueAt(double angle, double, double h) const override {
    return k_ * (angle - speed_ * (time_ + h));
  }
  void Advance(double, double, double h) override { time_ += h; }
  double time() const { return time_; }

 private:
  double k_;      // [N m/rad]
  double speed_;  // [rad/s]
  double time_ = 0;
};

TEST(Friction, StickSlipMatchesTheCoulombClosedForm) {
  DcMotorParameters p = BareRotor(1e-5);
  p.coulomb_friction = 0.01;
  p.static_friction = 0.02;
  p.stribeck_speed = 0.05;
  p.friction_smoothing_speed = 1e-4;
  DcMotor motor(p);
  const double k = 0.05;     // [N m/rad]
  const double speed = 0.5;  // [rad/s]
  DraggedSpring load(k, speed);
  const double dt = 1e-4;
  // slips start where the speed rises through 1 rad/s; the spring's peak pull before each
  std::vector<double> starts;
  std::vector<double> peaks;
  std::vector<double> troughs;
  double peak = 0;
  double trough = 1;
  double last_speed = 0;
  for (long i = 0; i < 60000; ++i) {
    motor.Step(0, dt, load);
    const double pull = k * (speed * load.time() - motor.state().spool_angle);
    peak = std::max(peak, pull);
    trough = std::min(trough, pull);
    const double w = motor.state().spool_speed;
    if (last_speed < 1 && w >= 1) {
      starts.push_back(load.time());
      peaks.push_back(peak);
      troughs.push_back(trough);
      peak = 0;
      trough = 1;
    }
    last_speed = w;
  }
  // J theta'' = K e - tau_c in a slip; it starts at e = tau_s / K and ends at rest, e
  // symmetric about tau_c / K; the stick then stretches the spring back at the belt's speed
  const double omega = std::sqrt(k / p.rotor_inertia);
  const double y0 = (p.static_friction - p.coulomb_friction) / k;
  const double phi = std::atan2(speed / omega, y0);
  const double slip = (kPi + 2 * phi) / omega;
  const double stick = 2 * (p.static_friction - p.coulomb_friction) / (k * speed);
  const double period = slip + stick;
  ASSERT_GE(starts.size(), 5u);
  for (size_t j = 2; j < starts.size(); ++j) {
    EXPECT_NEAR(starts[j] - starts[j - 1], period, 0.01 * period) << j;
    EXPECT_NEAR(peaks[j], p.static_friction, 0.01 * p.static_friction) << j;
    EXPECT_NEAR(troughs[j], 2 * p.coulomb_friction - p.static_friction, 0.01 * 0.02) << j;
  }
  std::printf(
      "stick-slip: period %.5f s (closed form %.5f s), peak pull %.5f N m (tau_s %.3f), "
      "trough %.5f N m (%.3f)\n",
      starts.back() - starts[starts.size() - 2], period, peaks.back(), p.static_friction,
      troughs.back(), 2 * p.coulomb_friction - p.static_friction);
}

TEST(Cogging, RotorSwingsInACoggingWellAsAPendulum) {
  DcMotorParameters p = BareRotor(2e-6);
  p.cogging_amplitude = 3e-3;  // [N m]
  p.cogging_count = 12;
  DcMotor motor(p);
  // released at rest from 0.8 rad of the cogging angle n theta: J theta'' = -A sin(n theta)
  const double amplitude = 0.8;
  DcMotorState s;
  s.spool_angle = amplitude / p.cogging_count;
  motor.set_state(s);
  const double dt = 1e-5;
  std::vector<double> crossings;
  double last = motor.state().spool_angle;
  double time = 0;
  while (crossings.size() < 9 && time < 1) {
    motor.Step(0, dt, 0.0);
    time += dt;
    const double angle = motor.state().spool_angle;
    if ((last > 0) != (angle > 0)) crossings.push_back(time - dt * angle / (angle - last));
    last = angle;
  }
  ASSERT_EQ(crossings.size(), 9u);
  const double measured = (crossings.back() - crossings.front()) / 4;
  const double omega0 = std::sqrt(p.cogging_amplitude * p.cogging_count / p.rotor_inertia);
  const double exact = 4 * boost::math::ellint_1(std::sin(amplitude / 2)) / omega0;
  EXPECT_NEAR(measured, exact, 2e-6 * exact);
  // and the torque it reports is the Fourier form's one harmonic, n periods per turn
  EXPECT_NEAR(motor.cogging_torque(),
              p.cogging_amplitude * std::sin(p.cogging_count * motor.state().spool_angle), 1e-15);
  std::printf(
      "cogging well: period %.7f s, elliptic closed form %.7f s (relative error %.2g; "
      "small-swing %.7f s)\n",
      measured, exact, std::abs(measured - exact) / exact, 2 * kPi / omega0);
}

TEST(Cogging, RippleOfARunningMotorHasTheCountPerTurn) {
  DcMotorParameters p;
  p.cogging_amplitude = 2e-3;
  p.cogging_count = 8;
  DcMotor motor(p);
  const double dt = 1e-4;
  for (int i = 0; i < 20000; ++i) motor.Step(3, dt, 0.0);
  // the speed over whole rotor turns, as a Fourier series in the rotor angle
  std::vector<double> angle;
  std::vector<double> speed;
  const double start = p.gear_ratio * motor.state().spool_angle;
  while (p.gear_ratio * motor.state().spool_angle - start < 2 * kPi * 20) {
    motor.Step(3, dt, 0.0);
    angle.push_back(p.gear_ratio * motor.state().spool_angle);
    speed.push_back(motor.motor_speed());
  }
  // the Fourier coefficients in the rotor angle, integrated over the angle (the samples are
  // uniform in time, not in angle), of the speed about its mean
  const double turns = angle.back() - angle.front();
  double mean = 0;
  for (size_t i = 1; i < angle.size(); ++i) mean += speed[i] * (angle[i] - angle[i - 1]);
  mean /= turns;
  auto harmonic = [&](int m) {
    double c = 0;
    double s = 0;
    for (size_t i = 1; i < angle.size(); ++i) {
      const double d = angle[i] - angle[i - 1];
      c += (speed[i] - mean) * std::cos(m * angle[i]) * d;
      s += (speed[i] - mean) * std::sin(m * angle[i]) * d;
    }
    return std::hypot(c, s) * 2 / turns;
  };
  const double at_count = harmonic(8);
  EXPECT_GT(at_count, 0.05);  // [rad/s]
  for (int m : {1, 2, 3, 5, 7, 9}) EXPECT_LT(harmonic(m), 0.02 * at_count) << m;
  std::printf("speed ripple at 8 per turn %.4f rad/s; at 1, 7, 16 per turn %.2g, %.2g, %.2g\n",
              at_count, harmonic(1), harmonic(7), harmonic(16));
}

sgal::Actuator MotorTendon() {
  sgal::Actuator a;
  a.name = "flexor";
  a.kind = "dc_motor_tendon";
  a.tendon = "t";
  a.parameters["stiffness"] = 2e4;
  a.parameters["damping"] = 20;
  a.parameters["rest_length"] = 0.1;
  a.parameters["pretension"] = 5;
  return a;
}

// a spring-loaded path: the tendon pulls a mass on a spring (explicit, exact enough for the
// comparison, which is bit for bit between two identical plants)
struct Plant {
  double x = 0.3;  // path length [m]
  double v = 0;    // [m/s]
  double Step(TendonActuator& a, double dt) {
    const double tension = a.tension();
    const double force = -400 * (x - 0.3) - tension;
    const double mean = v + 0.5 * dt * force / 0.5;
    const double end = v + dt * force / 0.5;
    a.Step(x, mean, dt, end);
    x += mean * dt;
    v = end;
    return x;
  }
};

TEST(Driver, CommandDelayIsTheLoopWithItsCommandsShiftedByHand) {
  const double dt = 1e-3;
  const int delay = 7;
  sgal::Actuator delayed_description = MotorTendon();
  delayed_description.parameters["command_delay"] = delay * dt;
  auto delayed = Make(delayed_description);
  auto plain = Make(MotorTendon());
  delayed->SetTimeStep(dt);
  plain->SetTimeStep(dt);
  delayed->Reset(0.3);
  plain->Reset(0.3);
  Plant a;
  Plant b;
  std::deque<double> issued(delay, 0.0);  // the plain loop's commands, applied 7 steps late
  double differs = 0;
  for (int i = 0; i < 3000; ++i) {
    // a PD loop on the path length toward 0.28 m
    const double target = 0.28;
    const double u_a = std::clamp(400 * (a.x - target) + 20 * a.v, -12.0, 12.0);
    const double u_b = std::clamp(400 * (b.x - target) + 20 * b.v, -12.0, 12.0);
    delayed->SetCommand(u_a);
    issued.push_back(u_b);
    plain->SetCommand(issued.front());
    issued.pop_front();
    a.Step(*delayed, dt);
    b.Step(*plain, dt);
    ASSERT_EQ(a.x, b.x) << "step " << i;
    ASSERT_EQ(delayed->tension(), plain->tension()) << "step " << i;
    differs = std::max(differs, std::abs(a.x - 0.3));
  }
  EXPECT_GT(differs, 0.005);  // the loop moved
  // the same loop without the delay settles differently: the delay has an effect
  auto direct = Make(MotorTendon());
  direct->SetTimeStep(dt);
  direct->Reset(0.3);
  Plant c;
  double gap = 0;
  Plant d;
  auto delayed2 = Make(delayed_description);
  delayed2->SetTimeStep(dt);
  delayed2->Reset(0.3);
  for (int i = 0; i < 300; ++i) {
    direct->SetCommand(std::clamp(400 * (c.x - 0.28) + 20 * c.v, -12.0, 12.0));
    delayed2->SetCommand(std::clamp(400 * (d.x - 0.28) + 20 * d.v, -12.0, 12.0));
    c.Step(*direct, dt);
    d.Step(*delayed2, dt);
    gap = std::max(gap, std::abs(c.x - d.x));
  }
  EXPECT_GT(gap, 1e-4);
}

TEST(Driver, DelayLineSurvivesSaveAndRestoreBitForBit) {
  sgal::Actuator description = MotorTendon();
  description.parameters["command_delay"] = 0.005;
  description.parameters["slew_rate"] = 400;
  description.parameters["thermal_resistance_winding_housing"] = 1.6;
  description.parameters["thermal_resistance_housing_ambient"] = 4.65;
  description.parameters["thermal_time_constant_winding"] = 41.6;
  description.parameters["thermal_time_constant_motor"] = 1120;
  description.parameters["coulomb_friction"] = 1e-3;
  description.parameters["cogging_amplitude"] = 5e-4;
  description.parameters["cogging_count"] = 14;
  auto a = Make(description);
  auto b = Make(description);
  a->SetTimeStep(1e-3);
  b->SetTimeStep(1e-3);
  a->Reset(0.3);
  Plant pa;
  std::vector<double> saved(a->StateSize());
  Plant pb;
  for (int i = 0; i < 400; ++i) {
    a->SetCommand(6 * std::sin(i * 0.05));
    if (i == 200) {
      a->SaveState(saved.data());
      b->RestoreState(saved.data());
      b->SetCommand(a->command());
      pb = pa;
    }
    if (i > 200) b->SetCommand(6 * std::sin(i * 0.05));
    pa.Step(*a, 1e-3);
    if (i >= 200) {
      pb.Step(*b, 1e-3);
      ASSERT_EQ(pa.x, pb.x) << i;
      ASSERT_EQ(a->Get("winding_temperature"), b->Get("winding_temperature")) << i;
      ASSERT_EQ(a->Get("driver_voltage"), b->Get("driver_voltage")) << i;
    }
  }
  EXPECT_GT(a->Get("winding_temperature"), 25.0);
}

TEST(Driver, PwmQuantisesAndSlewLimits) {
  sgal::Actuator description = MotorTendon();
  description.parameters["pwm_levels"] = 100;
  description.parameters["supply_voltage"] = 12;
  description.parameters["slew_rate"] = 1000;  // [V/s]: 1 V per 1 ms step
  auto a = Make(description);
  a->SetTimeStep(1e-3);
  a->Reset(0.3);
  a->SetCommand(5.05);  // 0.42083 of the supply: 42 steps of 0.12 V
  Plant p;
  for (int i = 1; i <= 8; ++i) {
    p.Step(*a, 1e-3);
    EXPECT_DOUBLE_EQ(a->Get("driver_voltage"), std::min(1.0 * i, 12 * 42 / 100.0)) << i;
  }
  a->SetCommand(-30);  // beyond the supply: a PWM cannot give more
  for (int i = 0; i < 30; ++i) p.Step(*a, 1e-3);
  EXPECT_DOUBLE_EQ(a->Get("driver_voltage"), -12);
}

TEST(Driver, RefusesDelaysBeyondItsLineAndBadValues) {
  sgal::Actuator description = MotorTendon();
  description.parameters["command_delay"] = 100.5;
  auto a = Make(description);
  try {
    a->SetTimeStep(1e-3);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("flexor"), std::string::npos) << m;
    EXPECT_NE(m.find("100500 time steps"), std::string::npos) << m;
    EXPECT_NE(m.find("at most 100000 "), std::string::npos) << m;
  }
  // live, the same bound
  description.parameters["command_delay"] = 0;
  auto live = Make(description);
  live->SetTimeStep(1e-3);
  live->Set("command_delay", 100);  // 100,000 steps: the longest line
  try {
    live->Set("command_delay", 100.001);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("100001 time steps"), std::string::npos) << m;
    EXPECT_NE(m.find("at most 100000 "), std::string::npos) << m;
  }
  EXPECT_EQ(live->Get("command_delay"), 100);
  description.parameters["pwm_levels"] = 10.5;
  EXPECT_THROW(Make(description), std::invalid_argument);
  description.parameters["pwm_levels"] = 0;
  description.parameters["thermal_resistance_housing_ambient"] = 4;  // the other three missing
  try {
    Make(description);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("thermal_resistance_winding_housing"), std::string::npos)
        << e.what();
  }
  description.parameters.erase("thermal_resistance_housing_ambient");
  description.parameters["static_friction"] = 1e-3;
  description.parameters["coulomb_friction"] = 2e-3;
  EXPECT_THROW(Make(description), std::invalid_argument);
  description.parameters["static_friction"] = 0;
  description.parameters["cogging_count"] = 2.5;
  EXPECT_THROW(Make(description), std::invalid_argument);
}

}  // namespace
}  // namespace caliper::actuators
