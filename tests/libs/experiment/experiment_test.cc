// Experiment files: defaults and experiments, sweeps named NAME-K, overrides, command schedules
// inline and from CSV, paths relative to the file, and errors that name the file, the experiment
// and the key.
#include "caliper/experiment/experiment.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

#include "comma_locale.h"

namespace caliper::experiment {
namespace {

namespace fs = std::filesystem;

const char kKnownKeys[] =
    "unknown key (known: name, scene, duration_s, every_n_steps, record, set, commands, "
    "commands_csv, sweep, experiments)";

// the FormatError's message, or "" when `fn` throws none
template <typename Fn>
std::string ErrorOf(Fn fn) {
  try {
    fn();
  } catch (const FormatError& e) {
    return e.what();
  }
  return "";
}

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

// the values of override `id`, or {} when there is none
std::vector<double> ValuesOf(const Experiment& e, const std::string& id) {
  for (const Override& o : e.overrides)
    if (o.id == id) return o.values;
  return {};
}

std::vector<std::string> Names(const std::vector<Experiment>& runs) {
  std::vector<std::string> names;
  for (const auto& e : runs) names.push_back(e.name);
  return names;
}

// a schedule as (time [s], actuator, value) tuples, which compare and print
using Row = std::tuple<double, std::string, double>;
std::vector<Row> Rows(const std::vector<Command>& schedule) {
  std::vector<Row> rows;
  for (const Command& c : schedule) rows.emplace_back(c.time_s, c.actuator, c.value);
  return rows;
}

// a valid experiment, for Validate
Experiment Valid() {
  Experiment e;
  e.name = "flex_1.a-b";
  e.scene = "/models/arm.dae";
  e.record = {"arm.elbow.position"};
  e.duration_s = 0.5;
  e.schedule = {{0.0, "elbow_flexor", 6}};
  return e;
}

// the keys every run needs, for files that test something else
const char kRequired[] =
    R"("scene": "arm.dae", "duration_s": 0.5, "record": ["arm.elbow.position"])";

class ExperimentFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/caliper_experiment_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  // writes `text` to `name` under the temporary directory and returns the file's path
  std::string Write(const std::string& name, const std::string& text) {
    const fs::path path = fs::path(dir_) / name;
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
    return path.string();
  }

  std::string dir_;
};

TEST_F(ExperimentFileTest, ReadsOneRunNamedAfterTheFileWithoutExperimentsList) {
  const std::string path = Write("single.json", R"({
    "scene": "arm.dae",
    "duration_s": 2.0,
    "every_n_steps": 10,
    "record": ["arm.elbow.position", "arm.hand.position"]
  })");
  const auto runs = LoadFile(path);
  ASSERT_EQ(runs.size(), 1u);
  const Experiment& e = runs[0];
  EXPECT_EQ(e.name, "single");
  EXPECT_EQ(e.scene, dir_ + "/arm.dae");
  EXPECT_EQ(e.duration_s, 2.0);
  EXPECT_EQ(e.every_n_steps, 10u);
  EXPECT_EQ(e.record, (std::vector<std::string>{"arm.elbow.position", "arm.hand.position"}));
  EXPECT_TRUE(e.overrides.empty());
  EXPECT_TRUE(e.schedule.empty());
}

TEST_F(ExperimentFileTest, ReadsDecimalPointsUnderACommaDecimalLocale) {
  // caliper-calibrate shows a Qt report: its process runs under the user's locale
  const std::string path = Write("german.json", R"({
    "scene": "arm.dae", "duration_s": 0.25, "record": ["arm.elbow.position"],
    "set": {"arm.elbow.stiffness": [1.5, 2.5e-1]},
    "commands": [[0.125, "elbow_flexor", 6.5]]
  })");
  const std::string csv =
      Write("schedule.csv", "time [s],actuator,value\n0.5,elbow_flexor,-1.25\n");
  CALIPER_COMMA_DECIMAL_LOCALE(locale);
  const auto runs = LoadFile(path);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].duration_s, 0.25);
  EXPECT_EQ(ValuesOf(runs[0], "arm.elbow.stiffness"), (std::vector<double>{1.5, 0.25}));
  EXPECT_EQ(Rows(runs[0].schedule), (std::vector<Row>{{0.125, "elbow_flexor", 6.5}}));
  EXPECT_EQ(Rows(LoadScheduleCsv(csv)), (std::vector<Row>{{0.5, "elbow_flexor", -1.25}}));
}

TEST_F(ExperimentFileTest, SamplesEveryStepByDefault) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + "}"));
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].every_n_steps, 1u);
}

TEST_F(ExperimentFileTest, TopLevelNameReplacesTheFileName) {
  const auto runs =
      LoadFile(Write("a.json", std::string("{\"name\": \"elbow\", ") + kRequired + "}"));
  EXPECT_EQ(Names(runs), (std::vector<std::string>{"elbow"}));
}

TEST_F(ExperimentFileTest, ReadsASingleStringAsOneRecordedId) {
  const auto runs = LoadFile(
      Write("a.json", R"({"scene": "arm.dae", "duration_s": 1, "record": "arm.elbow.position"})"));
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].record, (std::vector<std::string>{"arm.elbow.position"}));
}

TEST_F(ExperimentFileTest, ResolvesScenePathRelativeToFile) {
  const auto runs = LoadFile(Write("deep/er/exp.json", R"({
    "duration_s": 1, "record": ["x"],
    "experiments": [
      {"name": "up", "scene": "../../models/./arm.dae"},
      {"name": "here", "scene": "arm.zae"},
      {"name": "absolute", "scene": "/opt/models/arm.dae"}
    ]
  })"));
  ASSERT_EQ(runs.size(), 3u);
  EXPECT_EQ(runs[0].scene, dir_ + "/models/arm.dae");
  EXPECT_EQ(runs[1].scene, dir_ + "/deep/er/arm.zae");
  EXPECT_EQ(runs[2].scene, "/opt/models/arm.dae");
}

TEST_F(ExperimentFileTest, ReadsOverridesAsNumbersOrLists) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + R"(,
    "set": {"arm.forearm.mass": 0.4, "arm.gravity": [0, 0, -9.81], "arm.damping": "1e-3"}
  })"));
  ASSERT_EQ(runs.size(), 1u);
  const auto& o = runs[0].overrides;
  ASSERT_EQ(o.size(), 3u);
  EXPECT_EQ(o[0].id, "arm.forearm.mass");
  EXPECT_EQ(o[0].values, (std::vector<double>{0.4}));
  EXPECT_EQ(o[1].id, "arm.gravity");
  EXPECT_EQ(o[1].values, (std::vector<double>{0, 0, -9.81}));
  EXPECT_EQ(o[2].id, "arm.damping");
  EXPECT_EQ(o[2].values, (std::vector<double>{1e-3}));
}

TEST_F(ExperimentFileTest, ExperimentsAddToAndReplaceTheDefaults) {
  const auto runs = LoadFile(Write("a.json", R"({
    "scene": "arm.dae", "duration_s": 0.5, "every_n_steps": 4, "record": ["a"],
    "set": {"m": 1, "k": 2},
    "experiments": [
      {"name": "same"},
      {"name": "other", "set": {"m": 3, "c": 4}, "duration_s": 1.5, "record": ["b", "c"],
       "every_n_steps": 2, "scene": "other.dae"}
    ]
  })"));
  ASSERT_EQ(runs.size(), 2u);
  const Experiment& same = runs[0];
  EXPECT_EQ(same.name, "same");
  EXPECT_EQ(same.scene, dir_ + "/arm.dae");
  EXPECT_EQ(same.duration_s, 0.5);
  EXPECT_EQ(same.every_n_steps, 4u);
  EXPECT_EQ(same.record, (std::vector<std::string>{"a"}));
  ASSERT_EQ(same.overrides.size(), 2u);
  EXPECT_EQ(same.overrides[0].id, "m");
  EXPECT_EQ(same.overrides[1].id, "k");

  const Experiment& other = runs[1];
  EXPECT_EQ(other.scene, dir_ + "/other.dae");
  EXPECT_EQ(other.duration_s, 1.5);
  EXPECT_EQ(other.every_n_steps, 2u);
  EXPECT_EQ(other.record, (std::vector<std::string>{"b", "c"}));
  // a replaced override moves to the end: overrides are applied in order
  ASSERT_EQ(other.overrides.size(), 3u);
  EXPECT_EQ(other.overrides[0].id, "k");
  EXPECT_EQ(other.overrides[0].values, (std::vector<double>{2}));
  EXPECT_EQ(other.overrides[1].id, "m");
  EXPECT_EQ(other.overrides[1].values, (std::vector<double>{3}));
  EXPECT_EQ(other.overrides[2].id, "c");
  EXPECT_EQ(other.overrides[2].values, (std::vector<double>{4}));
}

TEST_F(ExperimentFileTest, NamesUnnamedExperimentsByPosition) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + R"(,
    "experiments": [{}, {"name": "middle"}, {"duration_s": 1}]
  })"));
  EXPECT_EQ(Names(runs), (std::vector<std::string>{"run1", "middle", "run3"}));
}

TEST_F(ExperimentFileTest, ExpandsSweepIntoNamedRuns) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + R"(,
    "set": {"arm.forearm.mass": 1.0, "arm.k": 7},
    "experiments": [
      {"name": "flex", "sweep": {"arm.forearm.mass": [0.3, 0.4, 0.5]}},
      {"name": "still"}
    ]
  })"));
  ASSERT_EQ(Names(runs), (std::vector<std::string>{"flex-0", "flex-1", "flex-2", "still"}));
  const double masses[] = {0.3, 0.4, 0.5};
  for (size_t k = 0; k < 3; ++k) {
    const auto& o = runs[k].overrides;
    ASSERT_FALSE(o.empty());
    // the sweep's value comes after the default, so it is the one that counts
    EXPECT_EQ(o.back().id, "arm.forearm.mass");
    EXPECT_EQ(o.back().values, (std::vector<double>{masses[k]})) << runs[k].name;
    EXPECT_EQ(ValuesOf(runs[k], "arm.k"), (std::vector<double>{7}));
  }
  EXPECT_EQ(runs[3].overrides.size(), 2u);
  EXPECT_EQ(ValuesOf(runs[3], "arm.forearm.mass"), (std::vector<double>{1.0}));
}

TEST_F(ExperimentFileTest, SweepsTheCartesianProductWithTheFirstKeySlowest) {
  const auto runs = LoadFile(Write("grid.json", std::string("{") + kRequired + R"(,
    "sweep": {"a": [1, 2], "b": [10, 20, 30]}
  })"));
  ASSERT_EQ(Names(runs),
            (std::vector<std::string>{"grid-0", "grid-1", "grid-2", "grid-3", "grid-4", "grid-5"}));
  const double a[] = {1, 1, 1, 2, 2, 2};
  const double b[] = {10, 20, 30, 10, 20, 30};
  for (size_t k = 0; k < runs.size(); ++k) {
    EXPECT_EQ(runs[k].overrides.size(), 2u) << runs[k].name;
    EXPECT_EQ(ValuesOf(runs[k], "a"), (std::vector<double>{a[k]})) << runs[k].name;
    EXPECT_EQ(ValuesOf(runs[k], "b"), (std::vector<double>{b[k]})) << runs[k].name;
  }
}

TEST_F(ExperimentFileTest, SweepsOverListValues) {
  const auto runs = LoadFile(Write("g.json", std::string("{") + kRequired + R"(,
    "sweep": {"arm.gravity": [[0, 0, -9.81], [0, 0, -1.62]]}
  })"));
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(ValuesOf(runs[0], "arm.gravity"), (std::vector<double>{0, 0, -9.81}));
  EXPECT_EQ(ValuesOf(runs[1], "arm.gravity"), (std::vector<double>{0, 0, -1.62}));
}

TEST_F(ExperimentFileTest, ZeroPadsTheSweepIndexToTheWidthOfTheLast) {
  const auto runs = LoadFile(Write("pad.json", std::string("{") + kRequired + R"(,
    "sweep": {"m": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}
  })"));
  ASSERT_EQ(runs.size(), 11u);
  EXPECT_EQ(runs[0].name, "pad-00");
  EXPECT_EQ(runs[9].name, "pad-09");
  EXPECT_EQ(runs[10].name, "pad-10");
  EXPECT_EQ(ValuesOf(runs[10], "m"), (std::vector<double>{10}));
}

TEST_F(ExperimentFileTest, ExperimentSweepReplacesTheTopLevelSweep) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + R"(,
    "sweep": {"m": [1, 2]},
    "experiments": [
      {"name": "inherits"},
      {"name": "own", "sweep": {"k": [5, 6, 7]}},
      {"name": "none", "sweep": {}}
    ]
  })"));
  ASSERT_EQ(Names(runs), (std::vector<std::string>{"inherits-0", "inherits-1", "own-0", "own-1",
                                                   "own-2", "none"}));
  EXPECT_EQ(ValuesOf(runs[1], "m"), (std::vector<double>{2}));
  EXPECT_EQ(runs[2].overrides.size(), 1u);
  EXPECT_EQ(ValuesOf(runs[4], "k"), (std::vector<double>{7}));
  EXPECT_TRUE(runs[5].overrides.empty());
}

TEST_F(ExperimentFileTest, SortsScheduleStably) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + R"(,
    "commands": [[0.5, "b", 1], [0.0, "a", 6], [0.5, "c", 2], [0.25, "a", 0], [0.5, "a", -1]]
  })"));
  ASSERT_EQ(runs.size(), 1u);
  const std::vector<Row> expected = {
      {0.0, "a", 6}, {0.25, "a", 0}, {0.5, "b", 1}, {0.5, "c", 2}, {0.5, "a", -1}};
  EXPECT_EQ(Rows(runs[0].schedule), expected);
}

TEST_F(ExperimentFileTest, EmptyCommandsClearTheInheritedSchedule) {
  const auto runs = LoadFile(Write("a.json", std::string("{") + kRequired + R"(,
    "commands": [[0.0, "elbow_flexor", 6.0]],
    "experiments": [{"name": "flex"}, {"name": "still", "commands": []}]
  })"));
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(Rows(runs[0].schedule), (std::vector<Row>{{0.0, "elbow_flexor", 6.0}}));
  EXPECT_TRUE(runs[1].schedule.empty());
}

TEST_F(ExperimentFileTest, ReadsScheduleCsv) {
  const std::string path = Write("schedule.csv",
                                 "time [s],actuator,value\r\n"
                                 "0.5,elbow_flexor,6\r\n"
                                 "\n"
                                 "0.25,\"elbow, extensor\",-1.5e-1\n"
                                 "0,elbow_flexor, 2\n");
  const std::vector<Row> expected = {
      {0.5, "elbow_flexor", 6}, {0.25, "elbow, extensor", -0.15}, {0.0, "elbow_flexor", 2}};
  EXPECT_EQ(Rows(LoadScheduleCsv(path)), expected);
}

TEST_F(ExperimentFileTest, ReadsAnEmptyScheduleCsv) {
  EXPECT_TRUE(LoadScheduleCsv(Write("s.csv", "time [s],actuator,value\n")).empty());
}

TEST_F(ExperimentFileTest, RejectsMalformedScheduleCsv) {
  const std::string short_line = Write("short.csv", "time [s],actuator,value\n0,a,1\n0.5,a\n");
  EXPECT_EQ(ErrorOf([&] { LoadScheduleCsv(short_line); }),
            short_line + ": line 3: expected time [s],actuator,value");
  const std::string long_line = Write("long.csv", "time [s],actuator,value\n0,a,1,2\n");
  EXPECT_EQ(ErrorOf([&] { LoadScheduleCsv(long_line); }),
            long_line + ": line 2: expected time [s],actuator,value");
  const std::string text = Write("text.csv", "time [s],actuator,value\n0,a,1\nsoon,a,1\n");
  EXPECT_EQ(ErrorOf([&] { LoadScheduleCsv(text); }),
            text + ": line 3: 'soon' is not a finite number");
  const std::string inf = Write("inf.csv", "time [s],actuator,value\n0,a,inf\n");
  EXPECT_EQ(ErrorOf([&] { LoadScheduleCsv(inf); }), inf + ": line 2: 'inf' is not a finite number");
  const std::string quote = Write("quote.csv", "time [s],actuator,value\n0,\"a,1\n");
  const std::string error = ErrorOf([&] { LoadScheduleCsv(quote); });
  EXPECT_TRUE(Contains(error, quote + ": line 2: "));
}

TEST_F(ExperimentFileTest, RejectsAMissingScheduleCsv) {
  const std::string path = dir_ + "/missing.csv";
  EXPECT_EQ(ErrorOf([&] { LoadScheduleCsv(path); }), path + ": cannot be read");
}

TEST_F(ExperimentFileTest, ReadsCommandsCsvRelativeToTheFileAndSortsIt) {
  Write("data/schedule.csv",
        "time [s],actuator,value\n"
        "0.25,elbow_extensor,4\n"
        "0,elbow_flexor,6\n"
        "0.25,elbow_flexor,0\n");
  const auto runs = LoadFile(Write("exp/a.json", std::string("{") + kRequired + R"(,
    "commands": [[0.0, "ignored", 1]],
    "experiments": [{"name": "csv", "commands_csv": "../data/schedule.csv"}, {"name": "inline"}]
  })"));
  ASSERT_EQ(runs.size(), 2u);
  const std::vector<Row> expected = {
      {0.0, "elbow_flexor", 6}, {0.25, "elbow_extensor", 4}, {0.25, "elbow_flexor", 0}};
  EXPECT_EQ(Rows(runs[0].schedule), expected);
  EXPECT_EQ(Rows(runs[1].schedule), (std::vector<Row>{{0.0, "ignored", 1}}));
}

TEST_F(ExperimentFileTest, RejectsUnknownKey) {
  const std::string top = Write("top.json", std::string("{") + kRequired + R"(, "durations": 1})");
  EXPECT_EQ(ErrorOf([&] { LoadFile(top); }), top + ": durations: " + kKnownKeys);

  const std::string inner = Write("inner.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "flex", "sceen": "arm.dae"}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(inner); }), inner + ": experiment 'flex': sceen: " + kKnownKeys);
}

TEST_F(ExperimentFileTest, NamesFileAndExperimentInErrors) {
  const std::string path = Write("errors.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "light"}, {"name": "heavy", "set": {"arm.mass": "heavy"}}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(path); }),
            path + ": experiment 'heavy': set.arm.mass: 'heavy' is not a finite number");

  const std::string unnamed = Write("unnamed.json", std::string("{") + kRequired + R"(,
    "experiments": [{}, {"duration_s": "long"}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(unnamed); }),
            unnamed + ": experiment 'run2': duration_s: 'long' is not a finite number");
}

TEST_F(ExperimentFileTest, NamesFileExperimentAndKeyWhenARunIsIncomplete) {
  const std::string path = Write("incomplete.json", R"({
    "duration_s": 1, "record": ["x"],
    "experiments": [{"name": "has", "scene": "arm.dae"}, {"name": "lacks"}]
  })");
  const std::string error = ErrorOf([&] { LoadFile(path); });
  EXPECT_TRUE(Contains(error, path + ": "));
  EXPECT_TRUE(Contains(error, "experiment 'lacks': scene: missing"));

  const std::string swept = Write("swept.json", R"({
    "scene": "arm.dae", "record": ["x"], "sweep": {"arm.mass": [1, 2]}
  })");
  const std::string swept_error = ErrorOf([&] { LoadFile(swept); });
  EXPECT_TRUE(Contains(swept_error, swept + ": "));
  EXPECT_TRUE(Contains(swept_error, "experiment 'swept-0': duration_s: must be in (0, 1e6] s"));
}

TEST_F(ExperimentFileTest, RejectsNamesThatCannotNameFiles) {
  const std::string path = Write("a.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "../escape"}]
  })");
  const std::string error = ErrorOf([&] { LoadFile(path); });
  EXPECT_TRUE(Contains(error, path + ": "));
  EXPECT_TRUE(Contains(error, "experiment '../escape': name: use letters, digits"));

  const std::string spaced = Write("my run.json", std::string("{") + kRequired + "}");
  EXPECT_TRUE(Contains(ErrorOf([&] { LoadFile(spaced); }), "experiment 'my run': name:"));
}

TEST_F(ExperimentFileTest, RejectsBadEveryNSteps) {
  for (const std::string bad : {"0", "-2", "1.5", "1e10"}) {
    const std::string path =
        Write("n.json", std::string("{") + kRequired + ", \"every_n_steps\": " + bad + "}");
    EXPECT_EQ(ErrorOf([&] { LoadFile(path); }),
              path + ": every_n_steps: must be a whole number >= 1")
        << bad;
  }
  const std::string text =
      Write("t.json", std::string("{") + kRequired + ", \"every_n_steps\": \"ten\"}");
  EXPECT_EQ(ErrorOf([&] { LoadFile(text); }),
            text + ": every_n_steps: 'ten' is not a finite number");
  const std::string inner = Write("i.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "sparse", "every_n_steps": 0}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(inner); }),
            inner + ": experiment 'sparse': every_n_steps: must be a whole number >= 1");
}

TEST_F(ExperimentFileTest, RejectsDuplicateNames) {
  const std::string path = Write("dup.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "a"}, {"name": "b"}, {"name": "a", "duration_s": 2}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(path); }), path + ": experiment 'a': the name is used twice");

  const std::string swept = Write("swept.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "m-1"}, {"name": "m", "sweep": {"mass": [1, 2]}}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(swept); }),
            swept + ": experiment 'm-1': the name is used twice");
}

TEST_F(ExperimentFileTest, RejectsMalformedJsonWithLine) {
  const std::string path = Write("broken.json",
                                 "{\n"
                                 "  \"scene\": \"arm.dae\",\n"
                                 "  \"duration_s\": 0.5,,\n"
                                 "  \"record\": [\"x\"]\n"
                                 "}\n");
  const std::string error = ErrorOf([&] { LoadFile(path); });
  EXPECT_EQ(error.rfind(path + ":3: ", 0), 0u) << error;
}

TEST_F(ExperimentFileTest, RejectsAMissingFile) {
  const std::string path = dir_ + "/missing.json";
  const std::string error = ErrorOf([&] { LoadFile(path); });
  EXPECT_EQ(error.rfind(path + ":", 0), 0u) << error;
}

TEST_F(ExperimentFileTest, RejectsMalformedValues) {
  struct Case {
    std::string json;   // after the required keys
    std::string error;  // after "path: "
  };
  const std::vector<Case> cases = {
      {R"("set": [1, 2])", "set: expected an object {\"id\": value, ...}"},
      {R"("set": {"m": {"x": 1}})", "set.m: expected a number or a list of numbers"},
      {R"("set": {"m": [1, [2]]})", "set.m: expected a number or a list of numbers"},
      {R"("set": {"m": true})", "set.m: 'true' is not a finite number"},
      {R"("commands": [[0, "a"]])", "commands: expected a list of [time_s, \"actuator\", value]"},
      {R"("commands": [[0, ["a"], 1]])",
       "commands: expected a list of [time_s, \"actuator\", value]"},
      {R"("commands": [[0, "a", "full"]])", "commands: 'full' is not a finite number"},
      {R"("sweep": {"m": 0.3})", "sweep: expected an object {\"id\": [value, value, ...], ...}"},
      {R"("sweep": {"m": []})", "sweep: expected an object {\"id\": [value, value, ...], ...}"},
      {R"("sweep": {"m": [0.3, "x"]})", "sweep.m: 'x' is not a finite number"},
      {R"("experiments": {"a": {}})", "experiments: expected a list of objects"},
      {R"("experiments": [])", "experiments: no experiment in the file"},
      {R"("experiments": [[1, 2]])", "experiment 'run1': expected an object with keys, not a list"},
  };
  for (const Case& c : cases) {
    const std::string path = Write("bad.json", std::string("{") + kRequired + ", " + c.json + "}");
    EXPECT_EQ(ErrorOf([&] { LoadFile(path); }), path + ": " + c.error) << c.json;
  }
  const std::string nan = Write("nan.json", R"({
    "scene": "arm.dae", "duration_s": "nan", "record": ["x"]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(nan); }), nan + ": duration_s: 'nan' is not a finite number");
  const std::string record = Write("record.json", R"({
    "scene": "arm.dae", "duration_s": 1, "record": [{"id": "x"}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(record); }), record + ": record: expected a list of strings");
}

TEST_F(ExperimentFileTest, RejectsNestedExperiments) {
  const std::string path = Write("nest.json", std::string("{") + kRequired + R"(,
    "experiments": [{"name": "outer", "experiments": [{"name": "inner"}]}]
  })");
  EXPECT_EQ(ErrorOf([&] { LoadFile(path); }),
            path + ": experiment 'outer': experiments: experiments do not nest");
}

// a sweep of `keys` keys of ten values each: 10^keys runs
std::string TenValueSweep(int keys) {
  std::string sweep = R"("sweep": {)";
  for (int k = 0; k < keys; ++k)
    sweep += (k ? ", " : "") + std::string("\"k") + std::to_string(k) +
             R"(": [1, 2, 3, 4, 5, 6, 7, 8, 9, 10])";
  return sweep + "}";
}

TEST_F(ExperimentFileTest, AcceptsUpToTheMostRunsAndRefusesMore) {
  ASSERT_EQ(kMaxRuns, 10000u);
  const std::string too_many =
      "sweep: more than 10000 runs in the file (the product of the numbers of values)";
  const auto runs =
      LoadFile(Write("big.json", std::string("{") + kRequired + ", " + TenValueSweep(4) + "}"));
  EXPECT_EQ(runs.size(), 10000u);
  // a few hundred bytes asking for a billion runs (it exhausted memory): refused before expanding
  const std::string bomb =
      Write("bomb.json", std::string("{") + kRequired + ", " + TenValueSweep(9) + "}");
  EXPECT_EQ(ErrorOf([&] { LoadFile(bomb); }), bomb + ": " + too_many);
  // the limit counts every experiment of the file
  const std::string two = Write("two.json", std::string("{") + kRequired + ", " + TenValueSweep(4) +
                                                R"(, "experiments": [{}, {}]})");
  EXPECT_EQ(ErrorOf([&] { LoadFile(two); }), two + ": experiment 'run2': " + too_many);
}

TEST(Validate, AcceptsAValidExperiment) {
  EXPECT_EQ(ErrorOf([] { Validate(Valid()); }), "");
}

TEST(Validate, RejectsEachMissingOrBadField) {
  struct Case {
    std::string what;
    void (*change)(Experiment*);
    std::string key;
  };
  const std::vector<Case> cases = {
      {"no name", [](Experiment* e) { e->name.clear(); }, "name: missing"},
      {"slash", [](Experiment* e) { e->name = "a/b"; }, "name: use letters"},
      {"space", [](Experiment* e) { e->name = "a b"; }, "name: use letters"},
      {"no scene", [](Experiment* e) { e->scene.clear(); }, "scene: missing"},
      {"zero duration", [](Experiment* e) { e->duration_s = 0; }, "duration_s: must be in"},
      {"negative duration", [](Experiment* e) { e->duration_s = -1; }, "duration_s: must be in"},
      {"long duration", [](Experiment* e) { e->duration_s = 2e6; }, "duration_s: must be in"},
      {"nan duration",
       [](Experiment* e) { e->duration_s = std::numeric_limits<double>::quiet_NaN(); },
       "duration_s: must be in"},
      {"no sampling", [](Experiment* e) { e->every_n_steps = 0; }, "every_n_steps: must be >= 1"},
      {"no record", [](Experiment* e) { e->record.clear(); }, "record: name at least one id"},
      {"no actuator", [](Experiment* e) { e->schedule[0].actuator.clear(); },
       "commands: a command without an actuator"},
      {"negative time",
       [](Experiment* e) {
         e->schedule.push_back({-0.1, "elbow_extensor", 1});
       },
       "commands: command 2 for 'elbow_extensor': time must be >= 0 s and the value finite"},
      {"infinite value",
       [](Experiment* e) { e->schedule[0].value = std::numeric_limits<double>::infinity(); },
       "commands: command 1 for 'elbow_flexor': time must be >= 0 s"},
  };
  for (const Case& c : cases) {
    Experiment e = Valid();
    c.change(&e);
    const std::string error = ErrorOf([&] { Validate(e); });
    EXPECT_TRUE(Contains(error, c.key)) << c.what;
    if (!e.name.empty()) {
      EXPECT_TRUE(Contains(error, "experiment '" + e.name + "'")) << c.what;
    }
  }
}

TEST(Validate, AcceptsTheLimitsOfTheDuration) {
  Experiment e = Valid();
  e.duration_s = 1e6;
  EXPECT_EQ(ErrorOf([&] { Validate(e); }), "");
  e.duration_s = 1e-9;
  EXPECT_EQ(ErrorOf([&] { Validate(e); }), "");
}

TEST(StepCount, RoundsToTheNearestStep) {
  EXPECT_EQ(StepCount(2.0, 0.001), 2000u);
  EXPECT_EQ(StepCount(0.5, 0.0005), 1000u);
  // 0.3 / 0.1 is 2.9999999999999996 in doubles: truncating would lose a step
  EXPECT_EQ(StepCount(0.3, 0.1), 3u);
  EXPECT_EQ(StepCount(1.0, 0.3), 3u);
  EXPECT_EQ(StepCount(0.75, 0.5), 2u);
  EXPECT_EQ(StepCount(0.2, 0.5), 0u);
  EXPECT_EQ(StepCount(0, 0.001), 0u);
}

TEST_F(ExperimentFileTest, RejectsKeysGivenTwice) {
  const std::string path = Write("twice.json", std::string("{") + kRequired +
                                                   R"(, "duration_s": 9})");
  const std::string error = ErrorOf([&] { LoadFile(path); });
  EXPECT_TRUE(Contains(error, path + ": duration_s: given twice")) << error;
}

TEST_F(ExperimentFileTest, RejectsValuesWhereObjectsOrListsBelong) {
  for (const std::string bad :
       {R"("experiments": ["oops", 7])", R"("set": 5)", R"("sweep": 3)", R"("commands": 5)",
        R"("commands": [{"t": 0, "a": "x", "v": 1}])"}) {
    const std::string path = Write("bad.json", std::string("{") + kRequired + ", " + bad + "}");
    EXPECT_FALSE(ErrorOf([&] { LoadFile(path); }).empty()) << bad << " was accepted";
  }
}

TEST_F(ExperimentFileTest, ScenePathIsAbsoluteWhenTheFileIsGivenRelative) {
  Write("rel/exp.json", std::string("{") + kRequired + "}");
  const fs::path here = fs::current_path();
  fs::current_path(dir_);
  const auto runs = LoadFile("rel/exp.json");
  fs::current_path(here);
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_TRUE(fs::path(runs[0].scene).is_absolute()) << runs[0].scene;
  EXPECT_EQ(runs[0].scene, dir_ + "/rel/arm.dae");
}

TEST_F(ExperimentFileTest, SweepOverridesKeepTheKeysOrder) {
  const auto runs = LoadFile(Write("order.json", std::string("{") + kRequired + R"(,
    "sweep": {"a.x": [1, 2], "b.y": [3]}})"));
  ASSERT_EQ(runs.size(), 2u);
  ASSERT_EQ(runs[1].overrides.size(), 2u);
  EXPECT_EQ(runs[1].overrides[0].id, "a.x");
  EXPECT_EQ(runs[1].overrides[0].values, std::vector<double>{2});
  EXPECT_EQ(runs[1].overrides[1].id, "b.y");
}

TEST_F(ExperimentFileTest, ScheduleCsvFieldsAreTrimmedAndErrorsNameTheExperimentFile) {
  const std::string csv = Write("s.csv", "time [s],actuator,value\n0.5, elbow_flexor , 3\n");
  const auto schedule = LoadScheduleCsv(csv);
  ASSERT_EQ(schedule.size(), 1u);
  EXPECT_EQ(schedule[0].actuator, "elbow_flexor");
  const std::string path = Write("uses_csv.json", std::string("{") + kRequired +
                                                      R"(, "commands_csv": "missing.csv"})");
  const std::string error = ErrorOf([&] { LoadFile(path); });
  EXPECT_TRUE(Contains(error, path + ": commands_csv: ")) << error;
  EXPECT_TRUE(Contains(error, "missing.csv")) << error;
}

TEST(StepCount, RejectsAZeroTimeStep) {
  EXPECT_THROW(StepCount(1.0, 0.0), FormatError);
  EXPECT_THROW(StepCount(1.0, -0.001), FormatError);
}

}  // namespace
}  // namespace caliper::experiment
