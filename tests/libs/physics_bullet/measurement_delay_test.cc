// Measurement delays (sgal::MeasurementDelay) in the Bullet adapter: a delayed channel reads its
// true value of d steps ago bit for bit, carries over through a saved (and recorded) dynamic
// state, follows a change of the time step, and a delay the scene cannot honour is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "caliper/collada/importer.h"
#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/recording/recording.h"

namespace caliper::physics_bullet {
namespace {

// the channels of models/pendulum_tendon.dae (time step 1 ms) the tests delay, and their lags
struct Channel {
  const char* id;
  double delay;  // [s]
  int steps;
};
const Channel kChannels[] = {
    {"motor.current", 0.004, 4}, {"pivot.position", 0.0, 0}, {"line.tendon.tension", 0.010, 10}};

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

sgal::Scene Pendulum() {
  const char* dir = std::getenv("CALIPER_SOURCE_DIR");
  sgal::Scene s = collada::Import(
      std::string(dir != nullptr ? dir : ".") + "/models/pendulum_tendon.dae", nullptr);
  for (const Channel& c : kChannels) s.measurement_delays.push_back({c.id, c.delay});
  return s;
}

// every channel's delayed and true value after each of `steps` steps, the motor driven by a slow
// sine of the step count (0 to 12 V, so that every channel moves): [step][channel], delayed at
// 2 k, true at 2 k + 1
std::vector<std::vector<double>> StepAndRead(sgal::PhysicsScene& scene, int steps) {
  std::vector<std::vector<double>> rows;
  for (int n = 0; n < steps; ++n) {
    scene.SetCommand("motor", 6 - 6 * std::cos(2 * M_PI * scene.steps() / 160.0));  // [V]
    scene.Step();
    std::vector<double> row;
    for (const Channel& c : kChannels) {
      row.push_back(scene.GetParameter(c.id));
      row.push_back(scene.GetParameter(std::string(c.id) + ".undelayed"));
    }
    rows.push_back(row);
  }
  return rows;
}

std::string Refusal(const sgal::Scene& s) {
  try {
    MakeScene(s);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "the scene loaded";
  return "";
}

TEST(MeasurementDelay, ADelayedChannelIsItsTrueValueStepsEarlierBitForBit) {
  const sgal::Scene s = Pendulum();
  auto scene = MakeScene(s);
  std::vector<double> at_load;
  for (const Channel& c : kChannels) {
    const int index = scene->ParameterIndex(std::string(c.id) + ".undelayed");
    ASSERT_GE(index, 0) << c.id;
    const sgal::ParameterInfo info = scene->Parameters()[index];  // Parameters() is a copy
    EXPECT_FALSE(info.writable);
    EXPECT_FALSE(info.is_static);
    EXPECT_EQ(info.unit, scene->Parameters()[scene->ParameterIndex(c.id)].unit);
    at_load.push_back(scene->GetParameter(index));
    EXPECT_TRUE(SameBits(scene->GetParameter(c.id), at_load.back())) << c.id;
  }
  const auto rows = StepAndRead(*scene, 200);
  for (size_t k = 0; k < std::size(kChannels); ++k) {
    const Channel& c = kChannels[k];
    SCOPED_TRACE(c.id);
    std::set<double> values;
    for (const auto& row : rows) values.insert(row[2 * k + 1]);
    EXPECT_GE(values.size(), 100u) << "the channel hardly moves";
    int differences = 0;
    for (int n = 0; n < 200; ++n) {
      // before the scene has run d steps: the value at load, as if constant since ever
      const double expected = n >= c.steps ? rows[n - c.steps][2 * k + 1] : at_load[k];
      if (!SameBits(rows[n][2 * k], expected) && ++differences <= 5)
        ADD_FAILURE() << "step " << n + 1 << ": " << rows[n][2 * k] << " != " << expected;
    }
    EXPECT_EQ(differences, 0);
  }
  // the DAQ reads by index: the same delayed value
  EXPECT_TRUE(SameBits(scene->GetParameter(scene->ParameterIndex("motor.current")),
                       scene->GetParameter("motor.current")));
}

TEST(MeasurementDelay, ASavedStateRestoredInAFreshSceneReadsOnBitForBit) {
  const sgal::Scene s = Pendulum();
  auto uninterrupted = MakeScene(s);
  StepAndRead(*uninterrupted, 100);
  // a recording keyframe: the state through its bytes, the caches reset on both sides
  const sgal::DynamicState saved = uninterrupted->SaveDynamicState();
  size_t remembered = 0;
  for (const Channel& c : kChannels) remembered += c.steps + 1;
  ASSERT_EQ(saved.measurements.size(), remembered);
  uninterrupted->ResetCaches();
  auto fresh = MakeScene(s);
  fresh->RestoreDynamicState(recording::DecodeState(recording::EncodeState(saved)));
  fresh->ResetCaches();
  const auto expected = StepAndRead(*uninterrupted, 100);
  const auto got = StepAndRead(*fresh, 100);
  int differences = 0;
  for (size_t n = 0; n < expected.size(); ++n)
    for (size_t k = 0; k < expected[n].size(); ++k)
      if (!SameBits(got[n][k], expected[n][k]) && ++differences <= 5)
        ADD_FAILURE() << "step " << 101 + n << ", value " << k << ": " << got[n][k]
                      << " != " << expected[n][k];
  EXPECT_EQ(differences, 0);
  // a state without measurements (an older recording) starts each channel at its present value
  sgal::DynamicState unknown = saved;
  unknown.measurements.clear();
  fresh->RestoreDynamicState(unknown);
  for (const Channel& c : kChannels)
    EXPECT_TRUE(
        SameBits(fresh->GetParameter(c.id), fresh->GetParameter(std::string(c.id) + ".undelayed")))
        << c.id;
  // one of another layout is refused, saying so
  sgal::DynamicState wrong = saved;
  wrong.measurements.pop_back();
  try {
    fresh->RestoreDynamicState(wrong);
    FAIL() << "a state of other delays was restored";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(remembered - 1) +
                                         " measurements for a scene whose 3 delayed channels "
                                         "hold " +
                                         std::to_string(remembered)),
              std::string::npos)
        << e.what();
  }
}

TEST(MeasurementDelay, ChangingTheTimeStepRecomputesTheSteps) {
  auto scene = MakeScene(Pendulum());
  StepAndRead(*scene, 50);
  // 2 ms: the current lags round(4 / 2) = 2 steps, the tension 5; the position still none
  scene->SetParameter("simulation.time_step", 0.002);
  const double current_now = scene->GetParameter("motor.current.undelayed");
  EXPECT_TRUE(SameBits(scene->GetParameter("motor.current"), current_now))
      << "the ring starts again from the present value";
  EXPECT_EQ(scene->SaveDynamicState().measurements.size(), 3u + 1u + 6u);
  const auto rows = StepAndRead(*scene, 20);
  for (int n = 2; n < 20; ++n) EXPECT_TRUE(SameBits(rows[n][0], rows[n - 2][1])) << n;
  for (int n = 5; n < 20; ++n) EXPECT_TRUE(SameBits(rows[n][4], rows[n - 5][5])) << n;
  EXPECT_TRUE(SameBits(rows[1][0], current_now));
  // a time step that would make a delay longer than 1000 steps is refused, nothing changed
  try {
    scene->SetParameter("simulation.time_step", 0.000005);
    FAIL() << "a lag of 2000 steps was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("measurement delay of 'line.tendon.tension': delay 0.01 s "
                                         "is 2000 steps of 5e-06 s, more than the 1000"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(scene->GetParameter("simulation.time_step"), 0.002);
  EXPECT_EQ(scene->SaveDynamicState().measurements.size(), 3u + 1u + 6u);
}

TEST(MeasurementDelay, RefusesADelayTheSceneCannotHonourNamingTheId) {
  struct Case {
    sgal::MeasurementDelay delay;
    const char* expected;
  };
  const Case cases[] = {
      {{"motor.curent", 0.001}, "measurement delay of 'motor.curent': the scene has no such"},
      {{"motor.current", -0.001},
       "measurement delay of 'motor.current': delay -0.001 s must be "
       "finite and not negative"},
      {{"motor.current", std::nan("")}, "'motor.current': delay nan s must be finite"},
      {{"motor.current", 1.002},
       "'motor.current': delay 1.002 s is 1002 steps of 0.001 s, "
       "more than the 1000 steps a channel may lag"},
      {{"pendulum.mass", 0.001}, "'pendulum.mass': a model parameter, not a measurement"},
      {{"simulation.time", 0.001}, "'simulation.time': the simulation's clock"},
      {{"pivot.position", 0.001}, "'pivot.position': the channel is delayed twice"},
      {{"motor.command", 0.001}, "'motor.command': it is written from outside"},
  };
  for (const Case& c : cases) {
    sgal::Scene s = Pendulum();
    s.measurement_delays.push_back(c.delay);
    const std::string message = Refusal(s);
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
    EXPECT_NE(message.find("pendulum_tendon.dae: "), std::string::npos) << message;
  }
  // 1000 steps is the most, and is taken
  sgal::Scene longest = Pendulum();
  longest.measurement_delays.push_back({"motor.motor_speed", 1.0});
  auto scene = MakeScene(longest);
  EXPECT_EQ(scene->SaveDynamicState().measurements.size(), 5u + 1u + 11u + 1001u);
  // and the rings together hold at most 20,000 values: 20 channels of 1000 steps, not 21
  sgal::Scene many = Pendulum();
  many.measurement_delays.clear();
  for (const auto& p : MakeScene(Pendulum())->Parameters())
    if (!p.is_static && !p.writable && p.id != "simulation.time" &&
        many.measurement_delays.size() < 21)
      many.measurement_delays.push_back({p.id, 1.0});
  ASSERT_EQ(many.measurement_delays.size(), 21u);
  const std::string message = Refusal(many);
  EXPECT_NE(message.find("the measurement delays hold 21021 values"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace caliper::physics_bullet
