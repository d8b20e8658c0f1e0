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

}  // namespace
}  // namespace caliper::calibration
