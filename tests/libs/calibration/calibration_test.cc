// Calibration files, measured CSVs, the search space's scaling and the cost: exact values on
// small hand-made data, and errors that name the file and what is wrong.
#include "caliper/calibration/calibration.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace caliper::calibration {
namespace {

namespace fs = std::filesystem;

class CalibrationFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper_calibration_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path) << text;
    return path;
  }
  std::string ErrorOf(const std::string& path) {
    try {
      LoadSpec(path);
    } catch (const SpecError& e) {
      return e.what();
    }
    return "";
  }
  std::string dir_;
};

const char kRuns[] = R"({"scene": "arm.dae", "duration_s": 1, "record": ["arm.elbow.position"],
  "experiments": [{"name": "a"}, {"name": "b"}]})";
const char kMeasured[] = "time [s],arm.elbow.position [rad]\n0,0\n1,1\n";

TEST(Parameter, MapsTheUnitIntervalLinearlyOrLogarithmically) {
  Parameter lin{"x", 2, 6, false};
  EXPECT_DOUBLE_EQ(lin.FromUnit(0.25), 3);
  EXPECT_DOUBLE_EQ(lin.ToUnit(5), 0.75);
  Parameter log{"k", 100, 10000, true};
  EXPECT_NEAR(log.FromUnit(0.5), 1000, 1e-9);
  EXPECT_NEAR(log.ToUnit(1000), 0.5, 1e-12);
  // outside the bounds: clamped to them
  EXPECT_DOUBLE_EQ(lin.FromUnit(1.5), 6);
  EXPECT_DOUBLE_EQ(log.ToUnit(1), 0);
}

TEST_F(CalibrationFiles, ReadsEverythingAndResolvesPathsAgainstTheFile) {
  Write("runs.json", kRuns);
  Write("a.csv", kMeasured);
  Write("b.csv", kMeasured);
  const Spec spec = LoadSpec(Write("cal.json", R"({
    "experiments": "runs.json", "measured": {"a": "a.csv", "b": "b.csv"},
    "parameters": [{"id": "arm.k", "lower": 1, "upper": 100, "scale": "log"},
                   {"id": "arm.m", "lower": 0.5, "upper": 2}],
    "channels": [{"id": "arm.elbow.position", "weight": 3, "window_s": [0.2, 0.8]}],
    "optimiser": {"algorithm": "xnes", "generations": 7, "population": 12, "sigma0": 0.1},
    "seed": 42})"));
  ASSERT_EQ(spec.experiments.size(), 2u);
  ASSERT_EQ(spec.measured.size(), 2u);
  EXPECT_EQ(spec.measured[1].file, dir_ + "/b.csv");
  EXPECT_EQ(spec.experiments[0].scene, dir_ + "/arm.dae");
  ASSERT_EQ(spec.parameters.size(), 2u);
  EXPECT_TRUE(spec.parameters[0].log_scale);
  EXPECT_FALSE(spec.parameters[1].log_scale);
  EXPECT_EQ(spec.channels.at("arm.elbow.position").weight, 3);
  EXPECT_EQ(spec.channels.at("arm.elbow.position").from_s, 0.2);
  EXPECT_EQ(spec.optimiser.algorithm, "xnes");
  EXPECT_EQ(spec.optimiser.generations, 7u);
  EXPECT_EQ(spec.optimiser.population, 12u);
  EXPECT_EQ(spec.seed, 42u);
}

TEST_F(CalibrationFiles, ErrorsNameTheFileAndTheProblem) {
  Write("runs.json", kRuns);
  Write("a.csv", kMeasured);
  const std::string base = R"("experiments": "runs.json", "measured": {"a": "a.csv", "b": "a.csv"})";
  const std::string cal = dir_ + "/cal.json";
  struct Case {
    std::string body, expected;
  };
  const Case cases[] = {
      {R"("experiments": "runs.json", "measured": {"a": "a.csv"}, "parameters": [{"id": "x", "lower": 1, "upper": 2}])",
       "measured: no file for experiment 'b'"},
      {base + R"(, "parameters": [])", "parameters: name at least one"},
      {base + R"(, "parameters": [{"id": "x", "lower": 2, "upper": 1}])", "'x': lower must be below upper"},
      {base + R"(, "parameters": [{"id": "x", "lower": 0, "upper": 1, "scale": "log"}])", "log scale needs lower > 0"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2, "scale": "cubic"}])", "scale is linear or log"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}, {"id": "x", "lower": 1, "upper": 2}])", "listed twice"},
      {base + R"(, "parameters": [{"id": "x", "lower": "one", "upper": 2}])", "'one' is not a finite number"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "optimiser": {"algorithm": "mine"})", "cmaes or xnes"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "colour": 1)", "unknown key 'colour'"},
      // a typo inside an entry is not taken for the default
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2, "scael": "log"}])",
       "parameters: 'x': unknown key 'scael' (known: id, lower, upper, scale)"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "channels": [{"id": "y", "wieght": 2}])",
       "channels: 'y': unknown key 'wieght'"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "channels": [{"weight": 2}])",
       "channels: an entry without \"id\""},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "optimiser": {"generation": 5})",
       "optimiser: unknown key 'generation'"},
      // found by fuzzing (tests/data/fuzz/calibration_spec/regressions): a negative seed was cast
      // to an unsigned (undefined), spans too wide mapped every value to inf or NaN
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "seed": -1)", "seed: a whole number in [0, 2^53]"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1, "upper": 2}], "seed": 1e300)", "seed: a whole number in [0, 2^53]"},
      {base + R"(, "parameters": [{"id": "x", "lower": -1e308, "upper": 1e308}])", "'x': upper - lower is too large"},
      {base + R"(, "parameters": [{"id": "x", "lower": 1e-300, "upper": 1e300, "scale": "log"}])", "'x': upper / lower is too large for a log scale"},
  };
  for (const auto& c : cases) {
    Write("cal.json", "{" + c.body + "}");
    const std::string error = ErrorOf(cal);
    EXPECT_NE(error.find(cal), std::string::npos) << error;
    EXPECT_NE(error.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << error;
  }
}

TEST_F(CalibrationFiles, MeasuredCsvErrorsNameTheCalibrationFileTheExperimentAndTheLine) {
  Write("runs.json", kRuns);
  Write("a.csv", kMeasured);
  const std::string bad = Write("bad.csv", "time [s],x [m]\n0,1\n0.5,oops\n");
  const std::string cal = Write("cal.json", R"({"experiments": "runs.json",
    "measured": {"a": "a.csv", "b": "bad.csv"},
    "parameters": [{"id": "x", "lower": 1, "upper": 2}]})");
  EXPECT_EQ(ErrorOf(cal),
            cal + ": measured: 'b': " + bad + ":3 column 2: 'oops' is not a finite number");
}

TEST_F(CalibrationFiles, MeasuredCsvErrorsNameTheLine) {
  const std::string bad = Write("bad.csv", "time [s],x [m]\n0,1\n0.5,oops\n");
  try {
    LoadMeasured(bad);
    FAIL();
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find(bad + ":3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadMeasured(Write("ms.csv", "time [ms],x [m]\n0,1\n1,2\n")), SpecError);
  EXPECT_THROW(LoadMeasured(Write("back.csv", "time [s],x [m]\n0,1\n0,2\n")), SpecError);
  EXPECT_THROW(LoadMeasured(Write("one.csv", "time [s],x [m]\n0,1\n")), SpecError);
  const Measured m = LoadMeasured(Write("ok.csv", "time [s],x[1] [m],y [-]\n0,1,5\n2,3,5\n"));
  EXPECT_EQ(m.columns, (std::vector<std::string>{"x[1]", "y"}));
  EXPECT_EQ(m.units, (std::vector<std::string>{"m", "-"}));
  EXPECT_DOUBLE_EQ(m.At(0, 0.5), 1.5);  // interpolated
  EXPECT_DOUBLE_EQ(m.At(0, 9), 3);      // held at the end
}

TEST(Cost, IsTheWeightedRmsOverTheMeasuredRangeInTheWindow) {
  Measured m;
  m.times = {0, 1, 2};
  m.columns = {"p", "v[1]"};
  m.units = {"rad", "m"};
  m.values = {{0, 2, 4}, {0, 0, 10}};
  experiment::Recording sim;
  sim.channels = {{"p", "rad", 1, 1}, {"v", "m", 3, 1}};
  sim.values_per_sample = 4;
  sim.times = {0, 0.5, 1, 1.5, 2, 2.5};  // 2.5 is past the measurements: not compared
  for (double t : sim.times) {
    const double p = 2 * t + 0.4;                 // off by 0.4 everywhere
    sim.data.insert(sim.data.end(), {p, 7, t < 1 ? 0 : 10 * (t - 1), 7});
  }
  std::map<std::string, ChannelWeight> weights;
  weights["v[1]"] = {3, 0.0, 2.0};
  const auto channels = CompareRecording(sim, m, weights);
  ASSERT_EQ(channels.size(), 2u);
  EXPECT_EQ(channels[0].column, "p");
  EXPECT_EQ(channels[0].samples, 5u);
  EXPECT_NEAR(channels[0].rms, 0.4, 1e-12);
  EXPECT_DOUBLE_EQ(channels[0].range, 4);
  EXPECT_EQ(channels[1].column, "v[1]");
  EXPECT_NEAR(channels[1].rms, 0, 1e-12);
  EXPECT_EQ(channels[1].weight, 3);
  // sqrt((1 * (0.4/4)^2 + 3 * 0) / 4)
  EXPECT_NEAR(Cost(channels), std::sqrt(0.01 / 4), 1e-12);
  // a window that leaves out the error
  weights["p"] = {1, 5, 6};
  EXPECT_EQ(CompareRecording(sim, m, weights)[0].samples, 0u);
  EXPECT_NEAR(Cost(CompareRecording(sim, m, weights)), 0, 1e-12);
}

TEST(Cost, NoComparableChannelIsAnError) {
  EXPECT_THROW(Cost({}), SpecError);
}

TEST(ColumnNames, FollowRecordingCsvs) {
  EXPECT_EQ(ColumnNames({{"a", "", 1, 1}, {"b", "", 3, 1}, {"c", "", 2, 2}}),
            (std::vector<std::string>{"a", "b[0]", "b[1]", "b[2]", "c[0][0]", "c[0][1]",
                                      "c[1][0]", "c[1][1]"}));
}


TEST_F(CalibrationFiles, ReadsTheTimingParametersStoppingRulesRefinementAndHeldOut) {
  Write("runs.json", kRuns);
  Write("a.csv", kMeasured);
  Write("b.csv", kMeasured);
  const Spec spec = LoadSpec(Write("cal.json", R"({
    "experiments": "runs.json", "measured": {"a": "a.csv", "b": "b.csv"},
    "parameters": [{"id": "arm.k", "lower": 1, "upper": 100, "scale": "log"},
                   {"id": "time_shift", "lower": -0.05, "upper": 0.05},
                   {"id": "sensor_delay:arm.elbow.position", "lower": 0, "upper": 0.02},
                   {"id": "command_delay:flexor", "lower": 0.001, "upper": 0.1, "scale": "log"}],
    "optimiser": {"generations": 80, "window": 12, "cost_tolerance": 1e-5,
                  "step_tolerance": 1e-3, "target_cost": 0.02, "restarts": 3},
    "refinement": {"iterations": 7, "jacobian": "forward", "step": 0.001},
    "uncertainty": {"max_relative_interval": 0.25, "max_correlation": 0.9},
    "held_out": ["b"]})"));
  ASSERT_EQ(spec.parameters.size(), 4u);
  EXPECT_EQ(spec.parameters[0].kind, ParameterKind::kScene);
  EXPECT_EQ(spec.parameters[0].Unit(), "");
  EXPECT_EQ(spec.parameters[1].kind, ParameterKind::kTimeShift);
  EXPECT_EQ(spec.parameters[1].target, "");
  EXPECT_EQ(spec.parameters[1].Unit(), "s");
  EXPECT_EQ(spec.parameters[2].kind, ParameterKind::kSensorDelay);
  EXPECT_EQ(spec.parameters[2].target, "arm.elbow.position");
  EXPECT_EQ(spec.parameters[3].kind, ParameterKind::kCommandDelay);
  EXPECT_EQ(spec.parameters[3].target, "flexor");
  EXPECT_TRUE(spec.parameters[3].log_scale);
  EXPECT_EQ(spec.parameters[3].Unit(), "s");
  EXPECT_EQ(spec.optimiser.generations, 80u);
  EXPECT_EQ(spec.optimiser.window, 12u);
  EXPECT_DOUBLE_EQ(spec.optimiser.cost_tolerance, 1e-5);
  EXPECT_DOUBLE_EQ(spec.optimiser.step_tolerance, 1e-3);
  EXPECT_DOUBLE_EQ(spec.optimiser.target_cost, 0.02);
  EXPECT_EQ(spec.optimiser.restarts, 3u);
  EXPECT_EQ(spec.refinement.iterations, 7u);
  EXPECT_FALSE(spec.refinement.central);
  EXPECT_DOUBLE_EQ(spec.refinement.step, 0.001);
  EXPECT_DOUBLE_EQ(spec.uncertainty.max_relative_interval, 0.25);
  EXPECT_DOUBLE_EQ(spec.uncertainty.max_correlation, 0.9);
  EXPECT_EQ(spec.held_out, (std::vector<bool>{false, true}));
  EXPECT_EQ(spec.Fitted(), 1u);
}

TEST_F(CalibrationFiles, TheNewKeysHaveDefaults) {
  Write("runs.json", kRuns);
  Write("a.csv", kMeasured);
  const Spec spec = LoadSpec(Write("cal.json", R"({
    "experiments": "runs.json", "measured": {"a": "a.csv", "b": "a.csv"},
    "parameters": [{"id": "arm.k", "lower": 1, "upper": 100}]})"));
  EXPECT_EQ(spec.held_out, (std::vector<bool>{false, false}));
  EXPECT_EQ(spec.Fitted(), 2u);
  EXPECT_EQ(spec.optimiser.window, 20u);
  EXPECT_DOUBLE_EQ(spec.optimiser.cost_tolerance, 1e-6);
  EXPECT_DOUBLE_EQ(spec.optimiser.step_tolerance, 1e-4);
  EXPECT_EQ(spec.optimiser.target_cost, 0);
  EXPECT_EQ(spec.optimiser.restarts, 2u);
  EXPECT_EQ(spec.refinement.iterations, 30u);
  EXPECT_TRUE(spec.refinement.central);
  EXPECT_DOUBLE_EQ(spec.refinement.step, 1e-3);
  EXPECT_DOUBLE_EQ(spec.uncertainty.max_relative_interval, 0.1);
  EXPECT_DOUBLE_EQ(spec.uncertainty.max_correlation, 0.95);
}

TEST_F(CalibrationFiles, RejectsBadTimingParametersRefinementAndHeldOut) {
  Write("runs.json", kRuns);
  Write("a.csv", kMeasured);
  const std::string base =
      R"("experiments": "runs.json", "measured": {"a": "a.csv", "b": "a.csv"}, )";
  const std::string x = R"("parameters": [{"id": "x", "lower": 1, "upper": 2}])";
  const std::string cal = dir_ + "/cal.json";
  struct Case {
    std::string body, expected;
  };
  const Case cases[] = {
      {base + x + R"(, "held_out": ["c"])", "held_out: no experiment named 'c'"},
      {base + x + R"(, "held_out": ["a", "b"])", "held_out: every experiment is held out"},
      {base + R"("parameters": [{"id": "sensor_delay:", "lower": 0, "upper": 1}])",
       "'sensor_delay:': name the measured column: sensor_delay:CHANNEL"},
      {base + R"("parameters": [{"id": "command_delay:", "lower": 0, "upper": 1}])",
       "'command_delay:': name the actuator: command_delay:ACTUATOR"},
      {base +
           R"("parameters": [{"id": "sensor_delay:arm.wrist.position", "lower": 0, "upper": 1}])",
       "no measured file has a column 'arm.wrist.position'"},
      {base + R"("parameters": [{"id": "foo:bar", "lower": 0, "upper": 1}])",
       "'foo:bar': unknown kind 'foo:'"},
      {base + R"("parameters": [{"id": "command_delay:flexor", "lower": -0.1, "upper": 1}])",
       "a delay cannot be negative"},
      {base + x + R"(, "refinement": {"step": 0})", "refinement: step is in (0, 0.1]"},
      {base + x + R"(, "refinement": {"jacobian": "backward"})", "jacobian is central or forward"},
      {base + x + R"(, "refinement": {"iterations": 3, "tolerance": 1})",
       "refinement: unknown key 'tolerance'"},
      {base + x + R"(, "uncertainty": {"max_correlation": 1.5})", "max_correlation in (0, 1]"},
      {base + x + R"(, "uncertainty": {"max_corelation": 0.5})",
       "uncertainty: unknown key 'max_corelation'"},
      {base + x + R"(, "optimiser": {"window": 1})", "optimiser: window"},
      {base + x + R"(, "optimiser": {"cost_tolerance": -1})", "are >= 0"},
  };
  for (const auto& c : cases) {
    Write("cal.json", "{" + c.body + "}");
    const std::string error = ErrorOf(cal);
    EXPECT_NE(error.find(cal), std::string::npos) << error;
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "expected '" << c.expected << "' in: " << error;
  }
}

TEST(TimingOf, CollectsTheShiftAndTheDelaysByColumn) {
  const std::vector<Parameter> parameters = {
      {"arm.k", 1, 10, false, ParameterKind::kScene, ""},
      {"time_shift", -1, 1, false, ParameterKind::kTimeShift, ""},
      {"sensor_delay:q", 0, 1, false, ParameterKind::kSensorDelay, "q"},
      {"command_delay:flexor", 0, 1, false, ParameterKind::kCommandDelay, "flexor"}};
  const Timing t = TimingOf(parameters, {5, 0.1, 0.05, 0.2});
  EXPECT_DOUBLE_EQ(t.shift_s, 0.1);
  ASSERT_EQ(t.sensor_delay_s.size(), 1u);
  EXPECT_DOUBLE_EQ(t.sensor_delay_s.at("q"), 0.05);
}

TEST(Cost, ATimeShiftComparesWithTheMeasurementsThatMuchLater) {
  // measured ramps p = t, q = 2 t over [0, 2]; the simulation has the same ramps
  Measured m;
  m.columns = {"p", "q"};
  m.units = {"rad", "m"};
  m.values.resize(2);
  for (int i = 0; i <= 20; ++i) {
    m.times.push_back(0.1 * i);
    m.values[0].push_back(0.1 * i);
    m.values[1].push_back(0.2 * i);
  }
  experiment::Recording sim;
  sim.channels = {{"p", "rad", 1, 1}, {"q", "m", 1, 1}};
  sim.values_per_sample = 2;
  for (int i = 0; i <= 6; ++i) {  // 0 to 1.5: t + 0.15 stays within the measurements
    const double t = 0.25 * i;
    sim.times.push_back(t);
    sim.data.insert(sim.data.end(), {t, 2 * t});
  }
  std::vector<double> residuals;
  Timing timing;
  timing.shift_s = 0.1;
  timing.sensor_delay_s["q"] = 0.05;
  const auto channels = CompareRecording(sim, m, {}, timing, &residuals);
  ASSERT_EQ(channels.size(), 2u);
  EXPECT_EQ(channels[0].unit, "rad");
  EXPECT_EQ(channels[1].unit, "m");
  EXPECT_EQ(channels[0].samples, 7u);
  EXPECT_EQ(channels[1].samples, 7u);
  // p(t) - p(t + 0.1) = -0.1; q(t) - q(t + 0.15) = -0.3
  EXPECT_NEAR(channels[0].rms, 0.1, 1e-12);
  EXPECT_NEAR(channels[1].rms, 0.3, 1e-12);
  ASSERT_EQ(residuals.size(), 14u);
  for (size_t i = 0; i < 7; ++i) {
    EXPECT_NEAR(residuals[i], -0.1, 1e-12) << i;
    EXPECT_NEAR(residuals[7 + i], -0.3, 1e-12) << i;
  }
  // without timing: a perfect fit; a negative shift the other way
  EXPECT_NEAR(Cost(CompareRecording(sim, m, {})), 0, 1e-12);
  residuals.clear();
  CompareRecording(sim, m, {}, Timing{-0.05, {}}, &residuals);
  ASSERT_EQ(residuals.size(), 14u);
  EXPECT_NEAR(residuals[3], 0.05, 1e-12);
  EXPECT_NEAR(residuals[10], 0.1, 1e-12);
  // which samples count depends on the simulated times only, not on the shift: past the end the
  // measurement is held (residual t - 2 at t = 1.75 and 2 with a shift of 0.5)
  sim.times.push_back(1.75);
  sim.times.push_back(2);
  sim.data.insert(sim.data.end(), {1.75, 3.5, 2, 4});
  residuals.clear();
  const auto late = CompareRecording(sim, m, {}, Timing{0.5, {}}, &residuals);
  EXPECT_EQ(late[0].samples, 9u);
  ASSERT_EQ(residuals.size(), 18u);
  EXPECT_NEAR(residuals[7], 1.75 - 2, 1e-12);
  EXPECT_NEAR(residuals[8], 0, 1e-12);
}

TEST(WithParameters, DelaysOneActuatorsCommandsAndOverridesOnlySceneParameters) {
  experiment::Experiment e;
  e.name = "steps";
  e.overrides = {{"arm.m", {1.5}}};
  e.schedule = {{0.0, "flexor", 1}, {0.1, "extensor", 2}, {0.2, "flexor", 3}, {0.3, "extensor", 4}};
  const std::vector<Parameter> parameters = {
      {"arm.k", 1, 10, false, ParameterKind::kScene, ""},
      {"command_delay:flexor", 0, 1, false, ParameterKind::kCommandDelay, "flexor"},
      {"time_shift", -1, 1, false, ParameterKind::kTimeShift, ""},
      {"sensor_delay:q", 0, 1, false, ParameterKind::kSensorDelay, "q"}};
  const experiment::Experiment out = WithParameters(e, parameters, {7, 0.15, 0.01, 0.02});
  ASSERT_EQ(out.overrides.size(), 2u);
  EXPECT_EQ(out.overrides[0].id, "arm.m");  // the experiment's own first
  EXPECT_EQ(out.overrides[1].id, "arm.k");
  EXPECT_EQ(out.overrides[1].values, (std::vector<double>{7}));
  ASSERT_EQ(out.schedule.size(), 4u);
  const std::vector<std::string> actuators = {"extensor", "flexor", "extensor", "flexor"};
  const std::vector<double> times = {0.1, 0.15, 0.3, 0.35};
  const std::vector<double> values = {2, 1, 4, 3};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(out.schedule[i].actuator, actuators[i]) << i;
    EXPECT_NEAR(out.schedule[i].time_s, times[i], 1e-12) << i;
    EXPECT_EQ(out.schedule[i].value, values[i]) << i;
  }
  // the experiment itself is unchanged; without a delay the schedule is as it was
  EXPECT_EQ(e.schedule[0].time_s, 0.0);
  const experiment::Experiment plain = WithParameters(e, {parameters[0]}, {7});
  ASSERT_EQ(plain.schedule.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(plain.schedule[i].time_s, e.schedule[i].time_s);
}

}  // namespace
}  // namespace caliper::calibration
