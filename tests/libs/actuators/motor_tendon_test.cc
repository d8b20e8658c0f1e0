// The dc_motor_tendon and ligament kinds through the registry: errors that name the actuator,
// the stall tension against a fixed path, quantities, the ligament law.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "caliper/actuators/actuator.h"
#include "caliper/actuators/dc_motor.h"
#include "caliper/sgal/scene.h"

namespace caliper::actuators {
namespace {

constexpr double kVoltage = 3;                      // [V]
constexpr double kStallCurrent = kVoltage / 0.516;  // U / R [A]

sgal::Actuator Motor() {
  sgal::Actuator a;
  a.name = "biceps_motor";
  a.kind = "dc_motor_tendon";
  a.tendon = "biceps";
  return a;
}

sgal::Actuator Ligament() {
  sgal::Actuator a;
  a.name = "knee_ligament";
  a.kind = "ligament";
  a.tendon = "acl";
  a.parameters["stiffness"] = 500;
  return a;
}

// At stall w = 0, so i = U / R and rho = rho(i, 0) (eta + 4.5e-5 (1/eta - eta)); the spool torque
// balances the motor torque through the gear: r_s F / (rho N) = k_t i.
double StallTension(double spool_radius, double voltage = kVoltage, double resistance = 0.516) {
  const double current = voltage / resistance;
  return 11.5e-3 * current * 128 * GearEfficiencyFactor(0.59, current, 0) / spool_radius;
}

std::string MessageOf(const sgal::Actuator& a) {
  try {
    Make(a);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

void RunFor(TendonActuator& actuator, double path_length, double duration, double dt = 1e-3) {
  const long steps = std::lround(duration / dt);
  for (long i = 0; i < steps; ++i) actuator.Step(path_length, 0, dt);
}

TEST(MotorKinds, AreRegisteredWithTheirParameters) {
  const auto kinds = Kinds();
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "dc_motor_tendon"), kinds.end());
  EXPECT_NE(std::find(kinds.begin(), kinds.end(), "ligament"), kinds.end());
  bool stiffness_required = false;
  for (const auto& spec : KindParameters("ligament"))
    if (spec.name == "stiffness") stiffness_required = spec.required;
  EXPECT_TRUE(stiffness_required);
  double resistance = 0;
  int count = 0;
  for (const auto& spec : KindParameters("dc_motor_tendon")) {
    if (spec.name == "resistance") resistance = spec.default_value;
    EXPECT_FALSE(spec.required) << spec.name;
    ++count;
  }
  EXPECT_EQ(resistance, 0.516);
  // motor (12 electrical and mechanical, 8 friction and cogging, 10 thermal), supply and
  // pretension, the driver (pwm_levels, slew_rate, command_delay), the elastic element
  EXPECT_EQ(count, 30 + 2 + 3 + 12);
}

TEST(MotorKinds, RejectUnknownKindsParametersAndOptionsNamingTheActuator) {
  sgal::Actuator a = Motor();
  a.kind = "dc_motor_tendonn";
  std::string message = MessageOf(a);
  EXPECT_TRUE(Contains(message, "biceps_motor")) << message;
  EXPECT_TRUE(Contains(message, "dc_motor_tendonn")) << message;

  a = Motor();
  a.parameters["resistence"] = 1;
  message = MessageOf(a);
  EXPECT_TRUE(Contains(message, "biceps_motor")) << message;
  EXPECT_TRUE(Contains(message, "unknown parameter 'resistence'")) << message;

  a = Ligament();
  a.parameters.erase("stiffness");
  message = MessageOf(a);
  EXPECT_TRUE(Contains(message, "knee_ligament")) << message;
  EXPECT_TRUE(Contains(message, "missing parameter 'stiffness'")) << message;

  a = Motor();
  a.options["input"] = "current";
  message = MessageOf(a);
  EXPECT_TRUE(Contains(message, "biceps_motor")) << message;
  EXPECT_TRUE(Contains(message, "input")) << message;

  a = Motor();
  a.options["elastic"] = "rubber";
  message = MessageOf(a);
  EXPECT_TRUE(Contains(message, "biceps_motor")) << message;
  EXPECT_TRUE(Contains(message, "rubber")) << message;
}

TEST(MotorKinds, RejectParameterValuesOutOfRangeNamingTheParameter) {
  for (const auto& [name, value] : {std::pair<std::string, double>{"resistance", -1},
                                    {"efficiency", 1.5},
                                    {"spool_radius", 0},
                                    {"supply_voltage", 0},
                                    {"pretension", -1},
                                    {"stiffness", 0},
                                    {"inductance", NAN}}) {
    sgal::Actuator a = Motor();
    a.parameters[name] = value;
    const std::string message = MessageOf(a);
    EXPECT_TRUE(Contains(message, "biceps_motor")) << message;
    EXPECT_TRUE(Contains(message, "'" + name + "'")) << message;
  }
  sgal::Actuator a = Ligament();
  a.parameters["damping"] = -2;
  const std::string message = MessageOf(a);
  EXPECT_TRUE(Contains(message, "knee_ligament")) << message;
  EXPECT_TRUE(Contains(message, "damping")) << message;
}

TEST(DcMotorTendon, PullsAFixedPathToTheStallTension) {
  sgal::Actuator a = Motor();
  a.parameters["stiffness"] = 2e5;
  a.parameters["rest_length"] = 0.05;
  auto motor = Make(a);
  motor->Reset(0.3);
  EXPECT_EQ(motor->tension(), 0);
  EXPECT_NEAR(motor->Get("line_length"), 0.25, 1e-12);
  motor->SetCommand(kVoltage);
  RunFor(*motor, 0.3, 0.5);
  const double early = motor->tension();
  RunFor(*motor, 0.3, 9.5);
  const double stall = StallTension(0.0045);  // 1122 N
  EXPECT_NEAR(stall, 1122.2, 0.1);
  EXPECT_GT(early, 0.3 * stall);
  EXPECT_LT(early, 0.9 * stall);
  EXPECT_NEAR(motor->tension(), stall, 0.002 * stall);
  EXPECT_EQ(motor->Get("tension"), motor->tension());
  EXPECT_NEAR(motor->Get("current"), kStallCurrent, 0.001 * kStallCurrent);
  EXPECT_LT(std::abs(motor->Get("spool_speed")), 1e-4);
  EXPECT_NEAR(motor->Get("elastic_length"), 0.05 + motor->tension() / 2e5, 1e-9);
  EXPECT_NEAR(motor->Get("line_length") + motor->Get("elastic_length"), 0.3, 1e-12);
  EXPECT_NEAR(motor->Get("spool_angle"), (0.25 - motor->Get("line_length")) / 0.0045, 1e-9);
  EXPECT_NEAR(motor->Get("voltage"), kVoltage, 1e-12);
  EXPECT_NEAR(motor->Get("power"), kVoltage * motor->Get("current"), 1e-9);
}

// A stalled geared motor is a stiff damper: the back-EMF resists winding with b = rho N^2 k_t k_e /
// (R r^2) at the line (1.2e5 N s/m for the shipped arm's motors), so a soft series spring K charges
// toward the stall tension with tau = (b + c) / K, c the element's own damper. With the arm's
// 3000 N/m that is 40.8 s: the demo's co-contracted elbow tensions creep up for minutes while the
// elbow stands still. The rotor and gear inertia (about 1,200 kg at the line) add a pole at
// b / m, about 100 /s, far from 1 / tau: the charge is one exponential to a few 1e-4.
TEST(DcMotorTendon, ChargesASoftSeriesSpringWithTheBackEmfTimeConstant) {
  constexpr double kVolts = 1, kStiffness = 3000, kDamper = 20, kPretension = 8;  // [V, N/m, N s/m, N]
  sgal::Actuator a = Motor();
  a.parameters["stiffness"] = kStiffness;
  a.parameters["damping"] = kDamper;
  a.parameters["pretension"] = kPretension;
  a.parameters["rest_length"] = 0.04;
  auto motor = Make(a);
  motor->Reset(0.3);
  motor->SetCommand(kVolts);
  const double stall = StallTension(0.0045, kVolts);  // 374 N
  const double rho = GearEfficiencyFactor(0.59, kVolts / 0.516, 0);
  const double b = rho * 128 * 128 * 11.5e-3 * 11.5e-3 / (0.516 * 0.0045 * 0.0045);
  const double tau = (b + kDamper) / kStiffness;
  EXPECT_NEAR(tau, 40.8, 0.05);
  double t = 0;
  for (const double until : {0.25 * tau, 0.5 * tau, tau, 2 * tau}) {
    RunFor(*motor, 0.3, until - t);
    t = until;
    const double expected = stall - (stall - kPretension) * std::exp(-t / tau);
    EXPECT_NEAR(motor->tension(), expected, 2e-4 * stall) << "at t = " << t << " s";
  }
  // still 13.5 % short of the stall tension after two time constants
  EXPECT_LT(motor->tension(), 0.9 * stall);
}

TEST(DcMotorTendon, WithAZenerElementStallsAtTheSameTension) {
  sgal::Actuator a = Motor();
  a.options["elastic"] = "zener";
  a.parameters["zener_area"] = 1e-3;
  a.parameters["rest_length"] = 0.05;
  a.parameters["spool_radius"] = 0.02;
  auto motor = Make(a);
  motor->Reset(0.3);
  motor->SetCommand(kVoltage);
  RunFor(*motor, 0.3, 25);
  const double stall = StallTension(0.02);  // 252 N
  EXPECT_NEAR(motor->tension(), stall, 0.005 * stall);
  // relaxed: s = E0 e
  EXPECT_NEAR(motor->Get("elastic_length"), 0.05 * (1 + stall / (0.694e6 * 1e-3)), 0.005 * 0.05);
  EXPECT_NEAR(motor->Get("stress"), stall / 1e-3, 0.005 * stall / 1e-3);
}

TEST(DcMotorTendon, AStatelessElementsDamperReadsThePathsSpeedAtTheEnd) {
  // the tension returned acts from the end of the step: a series damper there reads the path's
  // speed at the end (the engine's second-order estimate), not the step's mean; the states, and
  // so the spring's stretch, integrate along the mean either way
  for (const std::string elastic : {"linear", "polynomial", "table"}) {
    SCOPED_TRACE(elastic);
    sgal::Actuator a = Motor();
    a.options["elastic"] = elastic;
    a.parameters["damping"] = 5;  // [N s/m]
    a.parameters["rest_length"] = 0.05;
    a.parameters["pretension"] = 20;
    if (elastic == "polynomial") a.parameters["poly_c1"] = 3000, a.parameters["poly_c2"] = 1e5;
    if (elastic == "table") a.options["elastic_table"] = "0.01 30; 0.02 80";
    if (elastic == "linear") a.parameters["stiffness"] = 3000;
    auto mean = Make(a), end = Make(a);
    for (auto* m : {mean.get(), end.get()}) {
      m->Reset(0.3);
      m->SetCommand(1.0);
    }
    const double f_mean = mean->Step(0.3, 0.01, 1e-3, 0.01);
    const double f_end = end->Step(0.3, 0.01, 1e-3, 0.03);
    EXPECT_NEAR(f_end - f_mean, 5 * 0.02, 1e-9) << "damping x (end speed - mean speed)";
    EXPECT_EQ(mean->Get("spool_angle"), end->Get("spool_angle")) << "states along the mean";
  }
  // an element with states of its own integrated them along the mean: the end speed changes
  // nothing
  sgal::Actuator z = Motor();
  z.options["elastic"] = "zener";
  z.parameters["zener_area"] = 1e-3;
  z.parameters["rest_length"] = 0.05;
  auto mean = Make(z), end = Make(z);
  for (auto* m : {mean.get(), end.get()}) m->Reset(0.3);
  EXPECT_EQ(mean->Step(0.3, 0.01, 1e-3, 0.01), end->Step(0.3, 0.01, 1e-3, 0.03));
}

TEST(DcMotorTendon, DutyInputScalesTheSupplyVoltage) {
  sgal::Actuator a = Motor();
  a.options["input"] = "duty";
  a.parameters["supply_voltage"] = 12;
  auto motor = Make(a);
  EXPECT_EQ(motor->command_unit(), "");
  motor->Reset(0.3);
  motor->SetCommand(0.25);
  // the path shortened: the line is slack, the motor runs free
  RunFor(*motor, 0.25, 0.3);
  EXPECT_NEAR(motor->Get("voltage"), 3, 1e-12);
  EXPECT_NEAR(motor->Get("spool_speed"), 3 / (11.5e-3 * 128), 0.01 * 2.038);
  EXPECT_NEAR(motor->Get("motor_speed"), 128 * motor->Get("spool_speed"), 1e-9);
  EXPECT_EQ(motor->tension(), 0);
  EXPECT_LT(motor->Get("line_length"), 0.25);
  motor->SetCommand(2);
  EXPECT_EQ(motor->command(), 1);
  EXPECT_THROW(motor->SetCommand(NAN), std::invalid_argument);
}

TEST(DcMotorTendon, ReverseVoltagePaysOutLineAndSlackens) {
  sgal::Actuator a = Motor();
  a.parameters["pretension"] = 10;
  auto motor = Make(a);
  EXPECT_EQ(motor->command_unit(), "V");
  motor->Reset(0.3);
  EXPECT_NEAR(motor->tension(), 10, 1e-9);
  motor->SetCommand(-kVoltage);
  RunFor(*motor, 0.3, 2);
  EXPECT_EQ(motor->tension(), 0);
  EXPECT_NEAR(motor->Get("spool_speed"), -2.038, 0.01 * 2.038);
  // the elastic element (1000 N/m) started 10 mm long, the spool paid out 18 mm
  EXPECT_NEAR(motor->Get("line_length"), 0.3 - 0.06 + 0.0045 * 2.038 * (2 - 0.006), 3e-4);
  EXPECT_LT(motor->Get("elastic_length"), 0.05);
}

TEST(DcMotorTendon, PretensionSetsTheElasticLengthAtReset) {
  sgal::Actuator a = Motor();
  a.parameters["pretension"] = 20;
  a.parameters["stiffness"] = 1000;
  a.parameters["rest_length"] = 0.05;
  auto motor = Make(a);
  motor->Reset(0.4);
  EXPECT_NEAR(motor->Get("elastic_length"), 0.07, 1e-12);
  EXPECT_NEAR(motor->Get("line_length"), 0.33, 1e-12);
  EXPECT_NEAR(motor->tension(), 20, 1e-9);
  // unpowered, the gear gives way only slowly (back-driven through eta)
  EXPECT_NEAR(motor->Step(0.4, 0, 1e-3), 20, 0.01);
  EXPECT_LT(motor->Get("spool_speed"), 0);
}

TEST(DcMotorTendon, QuantitiesCanBeReadAndEdited) {
  sgal::Actuator a = Motor();
  a.parameters["stiffness"] = 2e5;
  auto motor = Make(a);
  bool found_current = false;
  bool found_resistance = false;
  for (const Quantity& q : motor->Quantities()) {
    if (q.name == "current") {
      found_current = true;
      EXPECT_EQ(q.unit, "A");
      EXPECT_FALSE(q.writable);
      EXPECT_FALSE(q.is_static);
    }
    if (q.name == "resistance") {
      found_resistance = true;
      EXPECT_EQ(q.unit, "ohm");
      EXPECT_TRUE(q.writable);
      EXPECT_TRUE(q.is_static);
    }
  }
  EXPECT_TRUE(found_current);
  EXPECT_TRUE(found_resistance);
  EXPECT_EQ(motor->Quantities().size(), 30u + 2u + 3u + 3u + 20u);
  EXPECT_EQ(motor->Get("gear_ratio"), 128);
  EXPECT_EQ(motor->Get("stiffness"), 2e5);

  try {
    motor->Set("resistance", 0);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "biceps_motor")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "resistance")) << e.what();
  }
  EXPECT_THROW(motor->Set("resistance", NAN), std::invalid_argument);
  EXPECT_THROW(motor->Set("tension", 5), std::invalid_argument);
  EXPECT_THROW(motor->Set("stiffness", -5), std::invalid_argument);
  EXPECT_THROW(motor->Set("torque", 1), std::out_of_range);
  EXPECT_THROW(motor->Get("torque"), std::out_of_range);
  EXPECT_THROW(motor->Get("zener_E0"), std::out_of_range);
  EXPECT_EQ(motor->Get("resistance"), 0.516);

  // doubling R halves the stall current and the stall tension
  motor->Set("resistance", 2 * 0.516);
  EXPECT_EQ(motor->Get("resistance"), 2 * 0.516);
  motor->Reset(0.3);
  motor->SetCommand(kVoltage);
  RunFor(*motor, 0.3, 10);
  EXPECT_NEAR(motor->Get("current"), kStallCurrent / 2, 0.001 * kStallCurrent);
  const double stall = StallTension(0.0045, kVoltage, 2 * 0.516);
  EXPECT_NEAR(motor->tension(), stall, 0.002 * stall);
  EXPECT_THROW(motor->Step(0.3, 0, 0), std::invalid_argument);
}

// the motor-tendon's state after 50 ms on a path lengthening at 0.02 m/s against 0.3 V, stepped
// with dt [s] and motor sub-steps as long as the step (max_substep 1 ms; the motion is smooth
// enough that none is refined), so that the error is that of the coupling with the path and of
// the motor's stages together
struct TendonEnd {
  double spool_speed;  // [rad/s]
  double current;      // [A]
  double spool_angle;  // [rad]
  double tension;      // [N]
};
TendonEnd LengtheningPathEnd(double dt) {
  sgal::Actuator a = Motor();
  a.parameters["max_substep"] = 1e-3;
  a.parameters["stiffness"] = 5e3;
  a.parameters["damping"] = 2;
  a.parameters["pretension"] = 5;
  auto motor = Make(a);
  motor->Reset(0.3);
  motor->SetCommand(0.3);
  const double speed = 0.02;  // [m/s]
  const long steps = std::lround(0.05 / dt);
  for (long i = 0; i < steps; ++i) motor->Step(0.3 + speed * i * dt, speed, dt);
  return {motor->Get("spool_speed"), motor->Get("current"), motor->Get("spool_angle"),
          motor->tension()};
}

TEST(DcMotorTendon, ConvergesWithSecondOrderOnALengtheningPath) {
  // the path seen at each stage's own time (the actuator contract): halving dt from 1 ms
  // divides every error by about 4 (holding the path at its start value through a step gave
  // about 2, first order, and a tension error of 0.1 N at 1 ms)
  const TendonEnd fine = LengtheningPathEnd(1e-5);
  const TendonEnd coarse = LengtheningPathEnd(1e-3);
  const TendonEnd half = LengtheningPathEnd(5e-4);
  EXPECT_GT(fine.tension, 8);  // taut and loaded: the spring pulls the spool back
  const double fine_values[] = {fine.spool_speed, fine.current, fine.spool_angle, fine.tension};
  const double coarse_values[] = {coarse.spool_speed, coarse.current, coarse.spool_angle,
                                  coarse.tension};
  const double half_values[] = {half.spool_speed, half.current, half.spool_angle, half.tension};
  const char* names[] = {"spool_speed", "current", "spool_angle", "tension"};
  for (int k = 0; k < 4; ++k) {
    const double coarse_error = std::abs(coarse_values[k] - fine_values[k]);
    const double half_error = std::abs(half_values[k] - fine_values[k]);
    EXPECT_GE(coarse_error, 3.5 * half_error) << names[k];
    EXPECT_GT(half_error, 0) << names[k];
  }
  // at 1 ms the tension is within 1e-6 N of the fine run
  EXPECT_NEAR(coarse.tension, fine.tension, 1e-6);
}

TEST(LigamentKind, IsASpringDamperInTensionOnly) {
  sgal::Actuator a = Ligament();
  a.parameters["damping"] = 2;
  a.parameters["rest_length"] = 0.1;
  auto ligament = Make(a);
  ligament->Reset(0.1);
  EXPECT_EQ(ligament->tension(), 0);
  // the tension at the end of the step: the path has moved by speed * dt
  EXPECT_NEAR(ligament->Step(0.12, 0.05, 1e-3), 500 * 0.02005 + 2 * 0.05, 1e-12);
  EXPECT_NEAR(ligament->tension(), 10.125, 1e-12);
  EXPECT_NEAR(ligament->Step(0.12, -0.5, 1e-3), 500 * 0.0195 - 2 * 0.5, 1e-12);
  EXPECT_EQ(ligament->Step(0.09, 0.5, 1e-3), 0);
  EXPECT_EQ(ligament->Step(0.102, -1.0, 1e-3), 0);  // taut, but the damping would push
  EXPECT_NEAR(ligament->Get("length"), 0.101, 1e-15);
  EXPECT_EQ(ligament->Get("speed"), -1.0);
  EXPECT_THROW(ligament->SetCommand(1), std::invalid_argument);
  EXPECT_THROW(ligament->Set("tension", 1), std::invalid_argument);
  EXPECT_THROW(ligament->Get("current"), std::out_of_range);
  ligament->Set("stiffness", 1000);
  EXPECT_NEAR(ligament->Step(0.12, 0, 1e-3), 20, 1e-12);
}

TEST(LigamentKind, RestLengthDefaultsToThePathLengthAtReset) {
  auto ligament = Make(Ligament());
  ligament->Reset(0.25);
  EXPECT_EQ(ligament->Get("rest_length"), 0.25);
  EXPECT_EQ(ligament->tension(), 0);
  EXPECT_NEAR(ligament->Step(0.26, 0, 1e-3), 5, 1e-9);
  ligament->Set("rest_length", 0.2);
  ligament->Reset(0.3);
  EXPECT_EQ(ligament->Get("rest_length"), 0.2);
  EXPECT_NEAR(ligament->tension(), 50, 1e-9);
}

}  // namespace
}  // namespace caliper::actuators
