// An experiment run's parts on their own, against a registry of fake channels: the last import
// remembered, overrides and their refusals, the checks before the first step with their messages,
// the schedule's commands as they fall due, and the samples (ImportCache, ApplyOverrides,
// ExperimentRunner).
#include "caliper/simulation/experiment_runner.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "caliper/simulation/core_types.h"

namespace caliper::simulation {
namespace {

using Commands = std::vector<std::pair<std::string, double>>;

/// Channels `m.x` (a scalar, the value of `x`, writable) and `m.v` (3 values: x, 2 x, 3 x, read
/// only, [m/s]); actuators `motor` and `brake`; an experiment of 1 s at a 10 ms step.
struct ExperimentRunnerTest : ::testing::Test {
  ExperimentRunnerTest() {
    registry.Add(
        {"m.x", "m", daq::Shape::Scalar(), false, false, "x"}, [this](double* out) { out[0] = x; },
        [this](const double* values) {
          if (values[0] < 0) throw std::invalid_argument("x must not be negative");
          x = values[0];
        });
    registry.Add({"m.v", "m/s", daq::Shape::Vector(3), false, false, "multiples of x"},
                 [this](double* out) {
                   for (int i = 0; i < 3; ++i) out[i] = (i + 1) * x;
                 });
    actuators.resize(2);
    actuators[0].name = "motor";
    actuators[1].name = "brake";
    e.name = "bend";
    e.duration_s = 1;
    e.every_n_steps = 10;
    e.record = {"m.v", "m.x"};
  }

  ExperimentRunner Make(uint64_t max_steps = 1000, size_t max_bytes = size_t{1} << 20) {
    return ExperimentRunner(e, registry, actuators, kDt, max_steps, max_bytes);
  }

  /// The message of what `f` throws as E ("" when it throws nothing).
  template <typename E, typename F>
  static std::string Thrown(F f) {
    try {
      f();
    } catch (const E& error) {
      return error.what();
    }
    return "";
  }

  static constexpr double kDt = 0.01;  // [s]
  double x = 1;
  daq::Registry registry;
  std::vector<sgal::Actuator> actuators;
  experiment::Experiment e;
};

TEST_F(ExperimentRunnerTest, ImportCacheImportsAFileOnceUntilItChanges) {
  ImportCache cache;
  int imports = 0;
  bool fail = false;
  const ImportCache::Importer import = [&](const std::string& name, const std::string& bytes) {
    ++imports;
    if (fail) throw std::runtime_error(name + " is broken");
    sgal::Scene scene;
    scene.name = name + ":" + bytes;
    return scene;
  };
  const auto a = cache.Get("arm.dae", "1", import);
  EXPECT_EQ(a->name, "arm.dae:1");
  EXPECT_EQ(cache.Get("arm.dae", "1", import), a);
  EXPECT_EQ(imports, 1);
  EXPECT_EQ(cache.Get("arm.dae", "2", import)->name, "arm.dae:2");
  EXPECT_EQ(cache.Get("leg.dae", "2", import)->name, "leg.dae:2");
  EXPECT_EQ(imports, 3);
  fail = true;
  EXPECT_EQ(Thrown<std::runtime_error>([&] { cache.Get("bad.dae", "3", import); }),
            "bad.dae is broken");
  fail = false;
  cache.Get("leg.dae", "2", import);  // the failure forgot the last scene
  EXPECT_EQ(imports, 5);
}

TEST_F(ExperimentRunnerTest, AppliesOverridesInOrderAndNamesARefusal) {
  e.overrides = {{"m.x", {3}}, {"m.x", {4}}};
  ApplyOverrides(e, registry);
  EXPECT_EQ(x, 4);
  e.overrides = {{"m.x", {5}}, {"m.y", {1}}};
  try {
    ApplyOverrides(e, registry);
    FAIL() << "applied";
  } catch (const UnknownId& error) {
    EXPECT_EQ(std::string(error.what()), "experiment 'bend': unknown id 'm.y' in set");
    EXPECT_EQ(error.id(), "m.y");
  }
  EXPECT_EQ(x, 5);  // the writes before it were made
  e.overrides = {{"m.x", {-1}}};
  EXPECT_EQ(Thrown<InvalidValue>([&] {
              ApplyOverrides(e, registry);
            }).rfind("experiment 'bend': set m.x: ", 0),
            0u);
  EXPECT_EQ(x, 5);
}

TEST_F(ExperimentRunnerTest, RecordsTheIdsWithTheirUnitsAndShapes) {
  ExperimentRunner run = Make();
  EXPECT_EQ(run.steps(), 100u);
  const experiment::Recording& rec = run.recording();
  ASSERT_EQ(rec.channels.size(), 2u);
  EXPECT_EQ(rec.channels[0].id, "m.v");
  EXPECT_EQ(rec.channels[0].unit, "m/s");
  EXPECT_EQ(rec.channels[0].rows, 3u);
  EXPECT_EQ(rec.channels[1].unit, "m");
  EXPECT_EQ(rec.values_per_sample, 4u);
  run.Sample(0);
  x = 2;
  run.Sample(0.1);
  EXPECT_EQ(rec.times, (std::vector<double>{0, 0.1}));
  EXPECT_EQ(rec.data, (std::vector<double>{1, 2, 3, 1, 2, 4, 6, 2}));
  EXPECT_FALSE(run.SampleDue(9));
  EXPECT_TRUE(run.SampleDue(10));
}

TEST_F(ExperimentRunnerTest, HandsOutCommandsAsTheyFallDue) {
  e.schedule = {{0, "motor", 1}, {0.05, "brake", 2}, {0.05, "motor", 3}, {0.5, "motor", 4}};
  ExperimentRunner run = Make();
  Commands pending;
  run.TakeDueCommands(0, &pending);
  EXPECT_EQ(pending, (Commands{{"motor", 1}}));
  run.TakeDueCommands(0.04, &pending);
  EXPECT_EQ(pending.size(), 1u);
  // a part per billion of a step short of 0.05 s still counts as due
  run.TakeDueCommands(0.05 - 0.5e-9 * kDt, &pending);
  EXPECT_EQ(pending, (Commands{{"motor", 1}, {"brake", 2}, {"motor", 3}}));
  run.TakeDueCommands(0.05, &pending);  // each only once
  EXPECT_EQ(pending.size(), 3u);
  run.TakeDueCommands(0.5 - 2e-9 * kDt, &pending);
  EXPECT_EQ(pending.size(), 3u);
  run.TakeDueCommands(0.6, &pending);
  EXPECT_EQ(pending.back(), (std::pair<std::string, double>{"motor", 4}));
}

TEST_F(ExperimentRunnerTest, RefusesUnknownIdsAndActuatorsBeforeTheFirstStep) {
  e.record = {"m.x", "m.w"};
  EXPECT_EQ(Thrown<UnknownId>([&] { Make(); }), "experiment 'bend': unknown id 'm.w' in record");
  e.record = {"m.x"};
  e.schedule = {{0, "motor", 1}, {0.1, "elbow", 1}};
  EXPECT_EQ(Thrown<UnknownId>([&] { Make(); }), "experiment 'bend': no actuator 'elbow'");
}

TEST_F(ExperimentRunnerTest, RefusesARunTooLongOrARecordingTooLargeSayingWhy) {
  EXPECT_EQ(Thrown<InvalidValue>([&] { Make(/*max_steps=*/99); }),
            "experiment 'bend': 100 steps of 0.010000 s; one run takes at most 99 (split it, or "
            "use a longer time step)");
  EXPECT_EQ(Thrown<InvalidValue>([&] { Make(100); }), "");
  // 11 samples of 4 values and a time: 440 bytes
  EXPECT_EQ(Thrown<InvalidValue>([&] { Make(100, 440); }), "");
  EXPECT_EQ(Thrown<InvalidValue>([&] { Make(100, 439); }),
            "experiment 'bend': 11 samples of 4 values are 0 MiB, more than one reply carries (0 "
            "MiB): sample less often (every_n_steps) or record fewer ids");
}

}  // namespace
}  // namespace caliper::simulation
