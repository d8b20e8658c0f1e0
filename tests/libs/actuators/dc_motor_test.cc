// The DC motor + gearbox + spool model against the reference motor of TENDONS.md.
#include "caliper/actuators/dc_motor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace caliper::actuators {
namespace {

// the reference (ECCE) motor of TENDONS.md
DcMotorParameters Reference() {
  DcMotorParameters p;
  p.resistance = 0.516;
  p.inductance = 5.73e-5;
  p.torque_constant = 11.5e-3;
  p.back_emf_constant = 11.5e-3;
  p.efficiency = 0.59;
  p.gear_ratio = 128;
  p.rotor_inertia = 14.5e-7;
  p.gear_inertia = 0.4e-7;
  return p;
}

constexpr double kVoltage = 3;                                        // [V]
constexpr double kNoLoadSpeed = kVoltage / (11.5e-3 * 128);           // U / (k_e N) [rad/s]
constexpr double kStallCurrent = kVoltage / 0.516;                    // U / R [A]
constexpr double kHoldTorque = kStallCurrent * 128 * 11.5e-3 / 0.59;  // (U/R) N k_t / eta [N m]

// steps the motor with a constant voltage and load for a duration
void RunFor(DcMotor& motor, double voltage, double load, double duration, double dt) {
  const long steps = std::lround(duration / dt);
  for (long i = 0; i < steps; ++i) motor.Step(voltage, dt, load);
}

// the CALIPER-era test: 3 V from t = 1 s, 10 N m load from 3 s to 4 s; spool speed sampled at
// the end of every step
std::vector<double> CaliperEraSpeeds(double dt, DcMotor& motor) {
  std::vector<double> speeds;
  const long steps = std::lround(5.0 / dt);
  for (long i = 0; i < steps; ++i) {
    const double t = i * dt;
    const double voltage = t >= 1.0 - 1e-12 ? kVoltage : 0.0;
    const double load = t >= 3.0 - 1e-12 && t < 4.0 - 1e-12 ? 10.0 : 0.0;
    motor.Step(voltage, dt, load);
    speeds.push_back(motor.state().spool_speed);
  }
  return speeds;
}

// the speed at the end of the step that ends at time t
double SpeedAt(const std::vector<double>& speeds, double dt, double t) {
  return speeds.at(std::lround(t / dt) - 1);
}

/// While the CALIPER-era scenario holds its load (3.5-4 s), consecutive 1 ms steps agree: no
/// oscillation around the gear efficiency's switch.
void ExpectSteadyWhileHeld(const std::vector<double>& speeds) {
  double low = 1e9;
  double high = -1e9;
  for (double t = 3.5; t < 3.999; t += 1e-3) {
    low = std::min(low, SpeedAt(speeds, 1e-3, t));
    high = std::max(high, SpeedAt(speeds, 1e-3, t));
  }
  EXPECT_LT(high - low, 1e-6);
}

TEST(DcMotor, ReferenceConstantsGiveTheDocumentedCheckValues) {
  EXPECT_NEAR(kNoLoadSpeed, 2.038, 5e-4);
  EXPECT_NEAR(kStallCurrent, 5.814, 5e-4);
  EXPECT_NEAR(kHoldTorque, 14.5, 0.05);
  DcMotor motor(Reference());
  EXPECT_NEAR(motor.inertia(), 14.9e-7, 1e-12);
}

TEST(DcMotor, RunsAtVoltageOverBackEmfWithoutLoad) {
  DcMotor motor(Reference());
  RunFor(motor, kVoltage, 0, 0.2, 1e-3);
  EXPECT_NEAR(motor.state().spool_speed, 2.038, 0.01 * 2.038);
  EXPECT_NEAR(motor.state().spool_speed, kNoLoadSpeed, 1e-9);
  EXPECT_NEAR(motor.motor_speed(), 128 * kNoLoadSpeed, 1e-6);
  EXPECT_NEAR(motor.state().current, 0, 1e-9);
  EXPECT_NEAR(motor.state().spool_angle, kNoLoadSpeed * (0.2 - 0.0059), 0.01);
}

TEST(DcMotor, SpeedRisesWithTheMechanicalTimeConstant) {
  DcMotor motor(Reference());
  const double tau = 0.516 * 14.9e-7 / (11.5e-3 * 11.5e-3);  // R J / (k_t k_e) = 5.8 ms
  EXPECT_NEAR(tau, 5.8e-3, 0.05e-3);
  const double dt = 1e-5;
  double t = 0;
  while (motor.state().spool_speed < (1 - std::exp(-1.0)) * kNoLoadSpeed && t < 0.1) {
    motor.Step(kVoltage, dt, 0.0);
    t += dt;
  }
  // the electrical lag adds about L/R = 0.11 ms
  EXPECT_NEAR(t, tau, 0.05 * tau);
}

TEST(DcMotor, StallCurrentIsVoltageOverResistance) {
  DcMotor motor(Reference());
  motor.set_locked(true);
  RunFor(motor, kVoltage, 0, 0.02, 1e-3);
  EXPECT_NEAR(motor.state().current, 5.814, 0.001 * 5.814);
  EXPECT_NEAR(motor.state().current, kStallCurrent, 1e-9);
  EXPECT_EQ(motor.state().spool_speed, 0);
  EXPECT_EQ(motor.state().spool_angle, 0);
  EXPECT_NEAR(motor.electrical_power(), kVoltage * kStallCurrent, 1e-6);
}

TEST(DcMotor, CurrentRisesWithTheElectricalTimeConstant) {
  DcMotor motor(Reference());
  motor.set_locked(true);
  const double tau = 5.73e-5 / 0.516;  // L / R = 0.111 ms
  const double dt = 1e-6;
  double t63 = -1;
  for (int i = 1; i <= 600; ++i) {
    motor.Step(kVoltage, dt, 0.0);
    const double t = i * dt;
    const double i_exact = kStallCurrent * (1 - std::exp(-t / tau));
    if (i % 50 == 0) {
      EXPECT_NEAR(motor.state().current, i_exact, 0.002 * i_exact) << "t " << t;
    }
    if (t63 < 0 && motor.state().current >= (1 - std::exp(-1.0)) * kStallCurrent) t63 = t;
  }
  EXPECT_NEAR(t63, 0.11e-3, 0.02 * 0.11e-3);
  EXPECT_NEAR(t63, tau, 1.5e-6);
}

TEST(DcMotor, GearEfficiencyFactorIsEtaDrivingAndInverseEtaBackDriven) {
  EXPECT_NEAR(GearEfficiencyFactor(0.59, 1, 1), 0.59, 1e-12);
  EXPECT_NEAR(GearEfficiencyFactor(0.59, 1, -1), 1 / 0.59, 1e-12);
  EXPECT_NEAR(GearEfficiencyFactor(0.59, -2, 1), 1 / 0.59, 1e-12);
  // tanh(-5): at rest the factor is within 5e-5 of eta
  EXPECT_NEAR(GearEfficiencyFactor(0.59, 0, 0), 0.59, 6e-5);
  EXPECT_GT(GearEfficiencyFactor(0.59, 0, 0), 0.59);
  // the middle of the switch at i w = -0.01
  EXPECT_NEAR(GearEfficiencyFactor(0.59, 1, -0.01), (0.59 + 1 / 0.59) / 2, 1e-12);
}

TEST(DcMotor, HoldsABackDrivingLoadBelowTheThreshold) {
  DcMotor motor(Reference());
  RunFor(motor, kVoltage, 0, 0.2, 1e-3);
  ASSERT_NEAR(motor.state().spool_speed, kNoLoadSpeed, 1e-6);
  const double load = 0.8 * kHoldTorque;  // 11.6 N m
  RunFor(motor, kVoltage, load, 0.5, 1e-3);
  const double angle = motor.state().spool_angle;
  RunFor(motor, kVoltage, load, 0.5, 1e-3);
  // the gear creeps backwards by a few mrad/s at most (the smooth efficiency switch)
  EXPECT_LT(motor.state().spool_speed, 0);
  EXPECT_GT(motor.state().spool_speed, -0.005);
  EXPECT_LT(std::abs(motor.state().spool_angle - angle), 0.0025);
  EXPECT_NEAR(motor.state().current, kStallCurrent, 0.01 * kStallCurrent);
}

TEST(DcMotor, IsBackDrivenByALoadAboveTheThreshold) {
  DcMotor motor(Reference());
  RunFor(motor, kVoltage, 0, 0.2, 1e-3);
  const double load = 1.2 * kHoldTorque;  // 17.4 N m
  RunFor(motor, kVoltage, load, 0.5, 1e-3);
  // back-driven: rho = 1/eta, k_t i = tau eta / N and i = (U - k_e N w) / R
  const double expected = (kVoltage - 0.516 * load * 0.59 / (128 * 11.5e-3)) / (11.5e-3 * 128);
  EXPECT_LT(expected, -0.3);
  EXPECT_NEAR(motor.state().spool_speed, expected, 0.01 * std::abs(expected));
  EXPECT_NEAR(motor.load_torque(), load, 1e-12);
}

TEST(DcMotor, CaliperEraScenarioRunsHoldsAndRunsAgain) {
  DcMotor motor(Reference());
  const double dt = 1e-3;
  const std::vector<double> w = CaliperEraSpeeds(dt, motor);
  EXPECT_EQ(SpeedAt(w, dt, 0.999), 0);
  EXPECT_NEAR(SpeedAt(w, dt, 2.999), 2.038, 0.01 * 2.038);
  // 10 N m < 14.5 N m: held, creeping back by about 1.7 mrad/s
  for (double t : {3.1, 3.5, 3.999}) {
    EXPECT_LE(SpeedAt(w, dt, t), 0) << "t " << t;
    EXPECT_GT(SpeedAt(w, dt, t), -0.003) << "t " << t;
  }
  EXPECT_NEAR(motor.state().spool_angle, 2.038 * 3.0, 0.05);
  EXPECT_NEAR(SpeedAt(w, dt, 4.999), 2.038, 0.01 * 2.038);
}

TEST(DcMotor, SubstepsAtOneMillisecondMatchAFineReferenceAndDoNotRing) {
  DcMotor coarse(Reference());
  DcMotor fine(Reference());
  const std::vector<double> w_coarse = CaliperEraSpeeds(1e-3, coarse);
  const std::vector<double> w_fine = CaliperEraSpeeds(1e-5, fine);
  for (double t : {1.002, 1.005, 1.01, 1.02, 1.05, 3.002, 3.005, 3.01, 3.5, 4.002, 4.005, 4.02}) {
    EXPECT_NEAR(SpeedAt(w_coarse, 1e-3, t), SpeedAt(w_fine, 1e-5, t), 0.005 * kNoLoadSpeed)
        << "t " << t;
  }
  EXPECT_NEAR(coarse.state().spool_angle, fine.state().spool_angle, 1e-4);
  ExpectSteadyWhileHeld(w_coarse);
}

TEST(DcMotor, CurrentLimitHoldsTheCurrentAtTheLimit) {
  DcMotorParameters p = Reference();
  p.current_limit = 2;
  DcMotor motor(p);
  motor.set_locked(true);
  double highest = 0;
  for (int i = 0; i < 200; ++i) {
    motor.Step(kVoltage, 1e-4, 0.0);
    highest = std::max(highest, motor.state().current);
  }
  EXPECT_LE(highest, 2 + 1e-9);
  EXPECT_NEAR(motor.state().current, 2, 1e-9);
  EXPECT_NEAR(motor.applied_voltage(), 0.516 * 2, 1e-6);
}

TEST(DcMotor, RoboyMotorRunsAtItsNoLoadSpeed) {
  DcMotorParameters p;
  p.resistance = 0.797;
  p.inductance = 0.118e-3;
  p.torque_constant = p.back_emf_constant = 14.2e-3;
  p.rotor_inertia = 4.09e-7;
  p.gear_inertia = 0.4e-7;
  p.gear_ratio = 53;
  p.efficiency = 0.59;
  DcMotor motor(p);
  RunFor(motor, kVoltage, 0, 0.2, 1e-3);
  EXPECT_NEAR(motor.state().spool_speed, kVoltage / (14.2e-3 * 53), 1e-6);
  EXPECT_NEAR(motor.state().spool_speed, 3.986, 0.001);
}

TEST(DcMotor, GearEfficiencyFactorIsTheTanhBlendOfTendonsMd) {
  for (double iw = -0.1; iw <= 0.1; iw += 1e-4) {
    const double blend = (std::tanh(-500 * iw - 5) + 1) / 2;
    EXPECT_NEAR(GearEfficiencyFactor(0.59, 1, iw), 0.59 + (1 / 0.59 - 0.59) * blend, 1e-15)
        << "i w " << iw;
  }
}

TEST(DcMotor, TheDefaultSubstepsMatchTheFineReferenceCloselyAndShorterOnesCloser) {
  // the fine-reference comparison of the test above, for the default sub-steps (1 ms, refined
  // to 1/3 ms after jumps), the earlier defaults 1/3 ms and 0.1 ms: errors reached 1.4e-4,
  // 1.4e-4 and 1.3e-5 rad/s
  DcMotor fine(Reference());
  const std::vector<double> w_fine = CaliperEraSpeeds(1e-5, fine);
  DcMotorParameters p = Reference();
  EXPECT_EQ(p.max_substep, 1e-3);
  for (double max_substep : {1e-3, 3.4e-4, 1e-4}) {
    p.max_substep = max_substep;
    DcMotor coarse(p);
    const std::vector<double> w_coarse = CaliperEraSpeeds(1e-3, coarse);
    double worst = 0;
    for (double t : {1.002, 1.005, 1.01, 1.02, 1.05, 3.002, 3.005, 3.01, 3.5, 4.002, 4.005, 4.02})
      worst = std::max(worst, std::abs(SpeedAt(w_coarse, 1e-3, t) - SpeedAt(w_fine, 1e-5, t)));
    EXPECT_LT(worst, max_substep > 2e-4 ? 3e-4 : 3e-5) << "max_substep " << max_substep;
    EXPECT_NEAR(coarse.state().spool_angle, fine.state().spool_angle, 1e-4);
  }
}

TEST(DcMotor, MillisecondSubstepsRefinedAfterJumpsMatchTheFineReferenceAsClosely) {
  // one sub-step per 1 ms step where the motion is smooth, redone in 1/3 ms ones just after the
  // voltage and load jumps: as close to the fine reference as 1/3 ms sub-steps throughout
  // (2.4e-3 rad/s without the refinement)
  DcMotor fine(Reference());
  const std::vector<double> w_fine = CaliperEraSpeeds(1e-5, fine);
  DcMotorParameters p = Reference();
  p.max_substep = 1e-3;
  DcMotor coarse(p);
  const std::vector<double> w_coarse = CaliperEraSpeeds(1e-3, coarse);
  double worst = 0;
  for (double t : {1.002, 1.005, 1.01, 1.02, 1.05, 3.002, 3.005, 3.01, 3.5, 4.002, 4.005, 4.02})
    worst = std::max(worst, std::abs(SpeedAt(w_coarse, 1e-3, t) - SpeedAt(w_fine, 1e-5, t)));
  EXPECT_LT(worst, 3e-4);
  EXPECT_NEAR(coarse.state().spool_angle, fine.state().spool_angle, 1e-4);
  ExpectSteadyWhileHeld(w_coarse);
  // where the motion is smooth the long sub-steps are taken: the speed differs from that of
  // 1/3 ms sub-steps (a refinement everywhere would give it to rounding)
  DcMotorParameters short_substeps = Reference();
  short_substeps.max_substep = 3.4e-4;
  DcMotor reference(short_substeps);
  const std::vector<double> w_short = CaliperEraSpeeds(1e-3, reference);
  EXPECT_GT(std::abs(SpeedAt(w_coarse, 1e-3, 1.05) - SpeedAt(w_short, 1e-3, 1.05)), 1e-7);
}

TEST(DcMotor, AStepAfterAVoltageJumpIsRefinedAndRepeatsBitForBitFromASavedState) {
  // running steadily at 3 V, then -3 V: the 1 ms sub-step is refused and redone as three of
  // 1/3 ms, which is what a motor with 1/3 ms sub-steps computes (to the exp() cache's rounding)
  DcMotor motor(Reference());
  DcMotorParameters short_substeps = Reference();
  short_substeps.max_substep = 1e-3 / 3;
  DcMotor reference(short_substeps);
  for (int i = 0; i < 200; ++i) motor.Step(kVoltage, 1e-3, 2.0);
  double saved[DcMotor::kStateSize];
  motor.SaveState(saved);
  reference.RestoreState(saved);
  motor.Step(-kVoltage, 1e-3, 2.0);
  reference.Step(-kVoltage, 1e-3, 2.0);
  const DcMotorState first = motor.state();
  EXPECT_NEAR(first.spool_speed, reference.state().spool_speed, 1e-12);
  EXPECT_NEAR(first.current, reference.state().current, 1e-12);
  EXPECT_LT(first.current, -5);  // reversed: the electrical transient the refinement follows
  // the refused sub-step leaves no trace: the same step from the saved state, also after
  // another step in between, gives the same bits
  motor.RestoreState(saved);
  motor.Step(-kVoltage, 1e-3, 2.0);
  EXPECT_EQ(motor.state().spool_speed, first.spool_speed);
  EXPECT_EQ(motor.state().current, first.current);
  motor.RestoreState(saved);
  motor.Step(kVoltage, 1e-3, 2.0);
  motor.RestoreState(saved);
  motor.Step(-kVoltage, 1e-3, 2.0);
  EXPECT_EQ(motor.state().spool_speed, first.spool_speed);
  EXPECT_EQ(motor.state().current, first.current);
  EXPECT_EQ(motor.state().spool_angle, first.spool_angle);
}

// a load known only through TorqueAt(): the motor differentiates it numerically and knows no
// affine range or sign
class OpaqueLoad : public SpoolLoad {
 public:
  explicit OpaqueLoad(double torque) : torque_(torque) {}
  double TorqueAt(double, double, double) const override { return torque_; }
  void Advance(double, double, double) override {}

 private:
  double torque_;
};

TEST(DcMotor, AnOpaqueLoadGivesWhatTheConstantLoadGives) {
  DcMotor known(Reference());
  DcMotor opaque(Reference());
  for (int i = 0; i < 3000; ++i) {
    const double t = i * 1e-3;
    const double voltage = t < 2 ? kVoltage : -kVoltage;
    const double load = t >= 1 && t < 1.5 ? 11.6 : (t >= 2.2 && t < 2.4 ? 20.0 : 0.0);
    known.Step(voltage, 1e-3, load);
    OpaqueLoad same(load);
    opaque.Step(voltage, 1e-3, same);
    ASSERT_NEAR(opaque.state().spool_speed, known.state().spool_speed, 1e-9) << "t " << t;
    ASSERT_NEAR(opaque.state().current, known.state().current, 1e-8) << "t " << t;
  }
}

TEST(DcMotor, AStageWithSeveralSolutionsTakesTheFirstFromItsBase) {
  // back-driven at 2.9 rad/s by 28 N m with the current reversing: an implicit stage of this step
  // has three solutions (near 2.68, 2.70 and 2.72 rad/s); the first from the stage's base speed,
  // which the bracketing search finds, gives 1.4333 rad/s at the end of the step (another
  // gives 1.3613; the fine-step solution is 1.4032)
  DcMotorParameters p = Reference();
  p.max_substep = 1e-4;
  DcMotor motor(p);
  DcMotorState s;
  s.current = 17.861130985985536;
  s.spool_speed = 2.8777802982414546;
  s.spool_angle = -3.7918841563628174;
  motor.set_state(s);
  motor.Step(-0.33577714971295014, 0.0013503518161756592, 28.283453493587231);
  EXPECT_NEAR(motor.state().spool_speed, 1.43332763, 1e-7);
  EXPECT_NEAR(motor.state().current, -5.058883524, 1e-7);
}

TEST(DcMotor, ChangingTheStepLengthRecomputesTheSubsteps) {
  // a motor that keeps its step constants against one that recomputes them for every step
  DcMotor kept(Reference());
  DcMotor fresh(Reference());
  const double steps[] = {1e-3, 2.5e-4, 1e-3, 5e-3, 7e-5, 1e-3};
  for (int round = 0; round < 50; ++round) {
    for (double dt : steps) {
      kept.Step(kVoltage, dt, 5.0);
      fresh.set_parameters(fresh.parameters());
      fresh.Step(kVoltage, dt, 5.0);
      ASSERT_NEAR(kept.state().spool_speed, fresh.state().spool_speed, 1e-12) << dt;
      ASSERT_NEAR(kept.state().current, fresh.state().current, 1e-12) << dt;
    }
  }
}

TEST(DcMotor, RejectsParametersOutOfRangeAndBadSteps) {
  DcMotorParameters p = Reference();
  p.resistance = -1;
  try {
    DcMotor motor(p);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("resistance"), std::string::npos) << e.what();
  }
  p = Reference();
  p.efficiency = 1.5;
  EXPECT_THROW(DcMotor{p}, std::invalid_argument);
  p = Reference();
  p.inductance = std::nan("");
  EXPECT_THROW(DcMotor{p}, std::invalid_argument);
  DcMotor motor(Reference());
  EXPECT_THROW(motor.Step(kVoltage, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(motor.Step(std::nan(""), 1e-3, 0.0), std::invalid_argument);
  EXPECT_EQ(motor.state().current, 0);
}

}  // namespace
}  // namespace caliper::actuators
