// The TendonActuator contract for every registered kind: SaveState/RestoreState put an actuator
// back where a repeated step gives the same result bit for bit; the work of one step is bounded
// (max_substep against the time step, the muscle's fibre sub-steps).
#include "caliper/actuators/actuator.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "caliper/actuators/dc_motor.h"
#include "caliper/sgal/scene.h"

namespace caliper::actuators {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// One configuration of a kind, with a path length it works at and a command.
struct Variant {
  std::string label;
  sgal::Actuator description;
  double path_length = 0.3;  // [m]
  double command = 0;
};

sgal::Actuator Describe(const std::string& kind, std::map<std::string, double> parameters,
                        std::map<std::string, std::string> options = {}) {
  sgal::Actuator a;
  a.name = "under_test";
  a.kind = kind;
  a.tendon = "t";
  a.parameters = std::move(parameters);
  a.options = std::move(options);
  return a;
}

/// Every configuration of the built-in kinds whose Step() changes different state.
std::map<std::string, std::vector<Variant>> BuiltinVariants() {
  const std::map<std::string, double> motor = {{"pretension", 5}};
  const std::map<std::string, double> thelen = {
      {"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}, {"max_isometric_force", 200}};
  const std::map<std::string, double> mujoco = {
      {"lengthrange_lo", 0.25}, {"lengthrange_hi", 0.35}, {"force", 100}};
  auto with = [](std::map<std::string, double> base, std::map<std::string, double> more) {
    for (const auto& [k, v] : more) base[k] = v;
    return base;
  };
  return {
      {"dc_motor_tendon",
       {{"linear", Describe("dc_motor_tendon", motor), 0.3, 0.05},
        {"zener", Describe("dc_motor_tendon", motor, {{"elastic", "zener"}}), 0.3, 0.05},
        {"polynomial",
         Describe("dc_motor_tendon", with(motor, {{"poly_c1", 800}, {"poly_c2", 2e4}}),
                  {{"elastic", "polynomial"}}),
         0.3, 0.05},
        {"table",
         Describe("dc_motor_tendon", motor,
                  {{"elastic", "table"}, {"elastic_table", "0.01 10; 0.02 30"}}),
         0.3, 0.05},
        {"duty, current limit",
         Describe("dc_motor_tendon", with(motor, {{"current_limit", 0.05}}), {{"input", "duty"}}),
         0.3, 0.02}}},
      {"ligament",
       {{"linear", Describe("ligament", {{"stiffness", 500}, {"damping", 5}, {"rest_length", 0.29}}),
         0.3, 0}}},
      {"hill_muscle",
       {{"thelen rigid", Describe("hill_muscle", thelen), 0.31, 0.5},
        {"thelen elastic", Describe("hill_muscle", thelen, {{"tendon", "elastic"}}), 0.31, 0.5},
        {"mujoco", Describe("hill_muscle", mujoco, {{"curves", "mujoco"}}), 0.3, 0.5},
        {"mujoco integrator",
         Describe("hill_muscle", mujoco, {{"curves", "mujoco"}, {"integrator", "mujoco"}}), 0.3,
         0.5}}},
  };
}

/// The variant's actuator at time step `dt`, reset on its path, with its command sent.
std::unique_ptr<TendonActuator> MakeReady(const Variant& v, double dt) {
  auto a = Make(v.description);
  a->SetTimeStep(dt);
  a->Reset(v.path_length);
  if (v.command != 0) a->SetCommand(v.command);
  return a;
}

/// Every quantity's value, in Quantities() order.
std::vector<double> Values(const TendonActuator& a) {
  std::vector<double> values;
  for (const Quantity& q : a.Quantities()) values.push_back(a.Get(q.name));
  return values;
}

void ExpectSameBits(const std::vector<double>& expected, const std::vector<double>& actual,
                    const TendonActuator& a, const std::string& when) {
  ASSERT_EQ(expected.size(), actual.size());
  const auto quantities = a.Quantities();
  for (size_t i = 0; i < expected.size(); ++i)
    EXPECT_TRUE(SameBits(expected[i], actual[i]))
        << when << ": " << quantities[i].name << " " << expected[i] << " != " << actual[i];
}

TEST(TendonActuator, EveryBuiltinKindHasRoundTripCases) {
  const auto variants = BuiltinVariants();
  for (const std::string& kind : Kinds()) {
    if (kind.rfind("test_", 0) == 0) continue;
    EXPECT_EQ(variants.count(kind), 1u) << "add the kind '" << kind << "' to BuiltinVariants()";
  }
}

TEST(TendonActuator, RestoredStateRepeatsTheStepBitForBit) {
  for (const auto& [kind, variants] : BuiltinVariants()) {
    for (const Variant& v : variants) {
      SCOPED_TRACE(kind + " (" + v.label + ")");
      const double dt = 1e-3;
      auto a = MakeReady(v, dt);
      // a moving path, so that every state (speeds, the Zener arm, the fibre) has something to do
      double length = v.path_length;
      for (int i = 0; i < 40; ++i) {
        const double speed = 0.02 * std::cos(i * 0.3);
        a->Step(length, speed, dt);
        length += speed * dt;
      }
      std::vector<double> saved(a->StateSize());
      a->SaveState(saved.data());
      const std::vector<double> before = Values(*a);
      const double tension_before = a->tension();

      const double first = a->Step(length, 0.015, dt);
      const std::vector<double> after = Values(*a);
      EXPECT_NE(first, 0) << "a case with no tension proves little";

      a->RestoreState(saved.data());
      ExpectSameBits(before, Values(*a), *a, "restored");
      EXPECT_TRUE(SameBits(a->tension(), tension_before));

      const double second = a->Step(length, 0.015, dt);
      EXPECT_TRUE(SameBits(first, second)) << first << " then " << second;
      ExpectSameBits(after, Values(*a), *a, "repeated step");

      // and again after a step that ran differently (other length and speed)
      a->RestoreState(saved.data());
      a->Step(length + 0.002, -0.05, dt);
      a->RestoreState(saved.data());
      EXPECT_TRUE(SameBits(a->Step(length, 0.015, dt), first));
      ExpectSameBits(after, Values(*a), *a, "step after another step was undone");

      // the engine sizes its buffer once
      EXPECT_EQ(a->StateSize(), saved.size());
    }
  }
}

TEST(TendonActuator, EachReaderReadsWhatGetReadsAsTheActuatorMoves) {
  // the DAQ reads every channel through Reader(name), made once at load: a reader must follow
  // the actuator as it steps and as its parameters are set, not keep what it read first.
  // dc_motor_tendon's and hill_muscle's Get go through the same tables as their readers, so
  // comparing with Get checks the table only for the default reader (ligament); the motor's
  // table is checked against closed forms at the end
  auto variants = BuiltinVariants();
  variants["dc_motor_tendon"].push_back(
      {"heat, friction, cogging, driver",
       Describe("dc_motor_tendon", {{"pretension", 5},
                                    {"thermal_resistance_winding_housing", 1.6},
                                    {"thermal_resistance_housing_ambient", 4.65},
                                    {"thermal_time_constant_winding", 41.6},
                                    {"thermal_time_constant_motor", 1120},
                                    {"coulomb_friction", 1e-4},
                                    {"cogging_amplitude", 1e-4},
                                    {"pwm_levels", 1024},
                                    {"command_delay", 0.003}}),
       0.3, 0.05});
  for (const auto& [kind, list] : variants) {
    for (const Variant& v : list) {
      SCOPED_TRACE(kind + " (" + v.label + ")");
      const double dt = 1e-3;
      auto a = MakeReady(v, dt);
      const auto quantities = a->Quantities();
      std::vector<std::function<double()>> readers;
      for (const Quantity& q : quantities) readers.push_back(a->Reader(q.name));
      double length = v.path_length;
      int differed = 0;  // readings that changed between the checks: the readers follow
      std::vector<double> last(quantities.size(), 0.0);
      for (int i = 0; i < 30; ++i) {
        const double speed = 0.02 * std::cos(i * 0.3);
        a->Step(length, speed, dt);
        length += speed * dt;
        if (i % 10 != 9) continue;
        for (size_t k = 0; k < quantities.size(); ++k) {
          const double got = readers[k]();
          EXPECT_TRUE(SameBits(got, a->Get(quantities[k].name)))
              << quantities[k].name << " at step " << i << ": reader " << got << ", Get "
              << a->Get(quantities[k].name);
          differed += i > 9 && !SameBits(got, last[k]);
          last[k] = got;
        }
      }
      EXPECT_GT(differed, 0) << "no reading changed as the actuator moved";
      // a parameter set later is read by the reader made before
      for (size_t k = 0; k < quantities.size(); ++k) {
        if (!quantities[k].writable || !quantities[k].is_static) continue;
        const double before = a->Get(quantities[k].name);
        try {
          a->Set(quantities[k].name, before * 1.001 + 1e-6);
        } catch (const std::invalid_argument&) {
          continue;  // out of its range: another parameter shows it
        }
        EXPECT_TRUE(SameBits(readers[k](), a->Get(quantities[k].name))) << quantities[k].name;
        a->Set(quantities[k].name, before);
      }
      EXPECT_THROW(a->Reader("no_such_quantity"), std::out_of_range);
      if (v.label != "heat, friction, cogging, driver") continue;
      // each of the motor's states reads what its name says (Get and Reader share the table)
      auto read = [&](const char* name) { return a->Reader(name)(); };
      EXPECT_DOUBLE_EQ(read("motor_speed"), read("gear_ratio") * read("spool_speed"));
      EXPECT_DOUBLE_EQ(read("power"), read("voltage") * read("current"));
      EXPECT_TRUE(SameBits(read("tension"), a->tension()));
      EXPECT_DOUBLE_EQ(read("delayed_command"), v.command);
      EXPECT_GT(read("winding_temperature"), read("housing_temperature"))
          << "the winding heats first";
      EXPECT_GT(read("housing_temperature"), read("ambient_temperature"));
      EXPECT_GT(read("hot_resistance"), read("resistance") * (1 + 1e-9)) << "a warm winding";
      EXPECT_NE(read("friction_torque"), 0);
      EXPECT_DOUBLE_EQ(
          read("cogging_torque"),
          read("cogging_amplitude") *
              std::sin(read("cogging_count") * read("gear_ratio") * read("spool_angle") +
                       read("cogging_phase")));
      EXPECT_NE(read("cogging_torque"), 0);
      // Coulomb's, smoothed, and viscous (no Stribeck peak without static_friction)
      EXPECT_DOUBLE_EQ(read("friction_torque"),
                       read("coulomb_friction") *
                               std::tanh(read("motor_speed") / read("friction_smoothing_speed")) +
                           read("viscous_friction") * read("motor_speed"));
      EXPECT_EQ(read("current_limit_now"), read("current_limit"));
      EXPECT_EQ(read("derating"), 0);
    }
  }
}

TEST(DcMotor, SaveStateRestoresTheExpCacheAndTheNewtonStartValue) {
  // a back-driving load the gear holds: i w stays near zero, where the efficiency switch is
  // smooth and exp() comes from the cache of the last exact value (which differs from exp()
  // in the last bits), and each stage's Newton iteration starts from the last acceleration
  DcMotor motor;
  for (int i = 0; i < 300; ++i) motor.Step(3, 1e-3, 10.0);
  double saved[DcMotor::kStateSize];
  motor.SaveState(saved);
  motor.Step(3, 1e-3, 10.0);
  const DcMotorState first = motor.state();
  for (int i = 0; i < 3; ++i) motor.Step(-0.5, 1e-3, 0.01);  // elsewhere entirely
  motor.RestoreState(saved);
  motor.Step(3, 1e-3, 10.0);
  EXPECT_TRUE(SameBits(motor.state().current, first.current));
  EXPECT_TRUE(SameBits(motor.state().spool_speed, first.spool_speed))
      << motor.state().spool_speed << " " << first.spool_speed;
  EXPECT_TRUE(SameBits(motor.state().spool_angle, first.spool_angle));
}

TEST(DcMotor, RefusesAStepNeedingMoreSubstepsThanTheBound) {
  DcMotorParameters p;
  p.max_substep = 1e-12;  // accepted on its own: the motor does not know the step yet
  DcMotor motor(p);
  try {
    motor.Step(3, 1e-3, 0.0);
    FAIL() << "1e9 sub-steps in one step";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "needs 1e+09 sub-steps, more than the 10000")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "max_substep must be at least 1e-07 s")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "or the time step at most 1e-08 s")) << e.what();
  }
  EXPECT_EQ(motor.state().current, 0) << "nothing ran";
  // exactly 10^4 sub-steps are allowed, one more is not
  EXPECT_NO_THROW(DcMotor::CheckSubsteps(1e-3, 1e-7));
  EXPECT_THROW(DcMotor::CheckSubsteps(1e-3, 0.9999e-7), std::invalid_argument);
  EXPECT_EQ(DcMotor::Substeps(1e-3, 1e-7), 10000);
  EXPECT_GT(DcMotor::Substeps(1e-3, 1e-300), 1e296) << "counted as a double, no overflow";
}

/// The number after `prefix` in a message.
double NumberAfter(const std::string& text, const std::string& prefix) {
  const size_t at = text.find(prefix);
  if (at == std::string::npos) return NAN;
  double value = NAN;
  std::from_chars(text.data() + at + prefix.size(), text.data() + text.size(), value);
  return value;
}

TEST(DcMotorTendon, RefusesAMaxSubstepTheTimeStepCannotAfford) {
  auto a = Make(Describe("dc_motor_tendon", {}));
  a->SetTimeStep(1e-3);
  try {
    a->Set("max_substep", 1e-12);
    FAIL() << "10^9 sub-steps per step accepted";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_TRUE(Contains(m, "actuator 'under_test' (dc_motor_tendon): parameter 'max_substep'"))
        << m;
    EXPECT_TRUE(Contains(m, "max_substep must be at least 1e-07 s")) << m;
  }
  EXPECT_EQ(a->Get("max_substep"), 1e-3) << "unchanged";
  EXPECT_THROW(a->Set("max_substep", 0), std::invalid_argument) << "still refused as before";
  a->Set("max_substep", 1e-7);  // the bound itself
  EXPECT_EQ(a->Get("max_substep"), 1e-7);

  // a longer time step is refused while max_substep holds; the actuator keeps the old one
  try {
    a->SetTimeStep(2e-3);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "or the time step at most 0.001 s")) << e.what();
  }
  EXPECT_THROW(a->Set("max_substep", 0.99e-7), std::invalid_argument) << "still 1 ms";
  EXPECT_THROW(a->SetTimeStep(0), std::invalid_argument);

  // the smallest value a message gives is accepted as it is printed, for any time step
  for (const double dt : {1e-3 / 3, 7.77e-4, 0.1 / 7}) {
    auto b = Make(Describe("dc_motor_tendon", {}));
    b->SetTimeStep(dt);
    try {
      b->Set("max_substep", dt / 2e4);
      FAIL();
    } catch (const std::invalid_argument& e) {
      const double smallest = NumberAfter(e.what(), "max_substep must be at least ");
      ASSERT_TRUE(std::isfinite(smallest)) << e.what();
      EXPECT_NO_THROW(b->Set("max_substep", smallest)) << e.what();
      EXPECT_LT(smallest, dt / 1e4 * (1 + 1e-6));
    }
  }
}

TEST(HillMuscle, RefusesATimeStepNeedingTooManyFibreSubsteps) {
  auto elastic = Make(Describe(
      "hill_muscle", {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.2}},
      {{"tendon", "elastic"}}));
  elastic->Reset(0.31);
  try {
    elastic->SetTimeStep(20);
    FAIL() << "2*10^4 fibre sub-steps of 1 ms in one step";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(Contains(e.what(), "hill_muscle 'under_test'")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "the time step must be at most 10 s")) << e.what();
  }
  EXPECT_NO_THROW(elastic->SetTimeStep(10));
  const double fibre = elastic->Get("fiber_length");
  EXPECT_THROW(elastic->Step(0.31, 0, 20), std::invalid_argument);
  EXPECT_EQ(elastic->Get("fiber_length"), fibre) << "nothing ran";
  // with a rigid tendon a step has no fibre sub-steps
  auto rigid = Make(Describe("hill_muscle", {{"optimal_fiber_length", 0.1},
                                             {"tendon_slack_length", 0.2}}));
  EXPECT_NO_THROW(rigid->SetTimeStep(20));
}

}  // namespace
}  // namespace caliper::actuators
