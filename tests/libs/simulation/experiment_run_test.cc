// ModelCore's experiment runs (what run_experiment serves), without CORBA: bit-identical
// recordings whatever ran before, the schedule and overrides taking effect, sampling, errors.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <iterator>
#include <thread>

#include "corpus.h"
#include "caliper/simulation/model_core.h"

namespace caliper::simulation {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::string ArmBytes() {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  const std::string bytes = ReadFile(std::string(src ? src : ".") + "/models/ecce_arm.dae");
  EXPECT_GT(bytes.size(), 1000u);
  return bytes;
}

experiment::Experiment Bend(double seconds = 0.3) {
  experiment::Experiment e;
  e.name = "bend";
  e.scene = "ecce_arm.dae";
  e.record = {"ecce_arm.elbow.position", "ecce_arm.hand.position"};
  e.every_n_steps = 10;
  e.duration_s = seconds;
  e.schedule = {{0.0, "elbow_flexor", 6.0}, {0.15, "elbow_flexor", 0.0}};
  return e;
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(ExperimentRun, SamplesAtStartAndEveryNStepsWithUnits) {
  ModelCore core;
  const RunResult r = core.RunExperiment(Bend(), "ecce_arm.dae", ArmBytes());
  const auto& rec = r.recording;
  const double dt = core.status().time_step;
  ASSERT_GT(dt, 0);
  EXPECT_EQ(r.steps, experiment::StepCount(0.3, dt));
  ASSERT_EQ(rec.times.size(), r.steps / 10 + 1);
  EXPECT_EQ(rec.times.front(), 0.0);
  EXPECT_NEAR(rec.times[1], 10 * dt, 1e-12);
  EXPECT_NEAR(rec.times.back(), 0.3, 1e-9);
  ASSERT_EQ(rec.channels.size(), 2u);
  EXPECT_EQ(rec.channels[0].unit, "rad");
  EXPECT_EQ(rec.channels[1].unit, "m");
  EXPECT_EQ(rec.channels[1].rows * rec.channels[1].cols, 3u);
  EXPECT_EQ(rec.values_per_sample, 4u);
  EXPECT_EQ(rec.data.size(), rec.times.size() * 4);
  // the flexor bent the elbow
  EXPECT_GT(std::abs(rec.data[(rec.times.size() - 1) * 4]), 0.01);
  EXPECT_EQ(core.status().state, RunState::kPaused);
  EXPECT_NEAR(core.status().sim_time, 0.3, 1e-9);
}

TEST(ExperimentRun, SameExperimentGivesSameBitsWhateverRanBefore) {
  const std::string arm = ArmBytes();
  ModelCore first;
  const RunResult a = first.RunExperiment(Bend(), "ecce_arm.dae", arm);

  // another Model that ran something else, with a command still set, then the same experiment
  ModelCore second;
  experiment::Experiment other = Bend(0.2);
  other.name = "other";
  other.schedule = {{0.0, "elbow_extensor", 5.0}};
  other.overrides = {{"ecce_arm.forearm.mass", {0.9}}};
  const RunResult b0 = second.RunExperiment(other, "ecce_arm.dae", arm);
  const RunResult b = second.RunExperiment(Bend(), "ecce_arm.dae", arm);

  EXPECT_TRUE(SameBits(a.recording.times, b.recording.times));
  EXPECT_TRUE(SameBits(a.recording.data, b.recording.data));
  EXPECT_FALSE(SameBits(a.recording.data, b0.recording.data));
}

TEST(ExperimentRun, OverridesAndScheduleChangeTheOutcome) {
  const std::string arm = ArmBytes();
  ModelCore core;
  const RunResult plain = core.RunExperiment(Bend(), "ecce_arm.dae", arm);
  experiment::Experiment heavy = Bend();
  heavy.overrides = {{"ecce_arm.forearm.mass", {1.5}}};
  const RunResult weighted = core.RunExperiment(heavy, "ecce_arm.dae", arm);
  experiment::Experiment idle = Bend();
  idle.schedule.clear();
  const RunResult still = core.RunExperiment(idle, "ecce_arm.dae", arm);
  const size_t last = (plain.recording.times.size() - 1) * 4;
  EXPECT_NE(plain.recording.data[last], weighted.recording.data[last]);
  EXPECT_GT(std::abs(plain.recording.data[last] - still.recording.data[last]), 0.01);
  // the override is a parameter of that run only: the next run starts from the file again
  const RunResult again = core.RunExperiment(Bend(), "ecce_arm.dae", arm);
  EXPECT_TRUE(SameBits(plain.recording.data, again.recording.data));
  EXPECT_NE(core.Sample({"ecce_arm.forearm.mass"})[0].values[0], 1.5);
}

TEST(ExperimentRun, RejectsUnknownIdsAndActuatorsBeforeStepping) {
  ModelCore core;
  const std::string arm = ArmBytes();
  experiment::Experiment e = Bend();
  e.record = {"ecce_arm.no_such.thing"};
  try {
    core.RunExperiment(e, "ecce_arm.dae", arm);
    FAIL() << "no error for an unknown recorded id";
  } catch (const UnknownId& error) {
    EXPECT_EQ(error.id(), "ecce_arm.no_such.thing");
    EXPECT_NE(std::string(error.what()).find("record"), std::string::npos);
  }
  e = Bend();
  e.schedule = {{0.0, "no_motor", 1.0}};
  EXPECT_THROW(core.RunExperiment(e, "ecce_arm.dae", arm), UnknownId);
  e = Bend();
  e.overrides = {{"ecce_arm.forearm.mass", {1.0, 2.0}}};
  EXPECT_THROW(core.RunExperiment(e, "ecce_arm.dae", arm), InvalidValue);
  EXPECT_EQ(core.status().steps, 0u);
}

TEST(ExperimentRun, BadSceneBytesNameTheFile) {
  ModelCore core;
  try {
    core.RunExperiment(Bend(), "broken.dae", "<COLLADA><oops");
    FAIL() << "no error for a broken scene";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("broken.dae"), std::string::npos) << error.what();
  }
  EXPECT_THROW(core.RunExperiment(Bend(), "scene.txt", ArmBytes()), std::runtime_error);
  EXPECT_THROW(core.LoadData("empty.dae", ""), std::runtime_error);
  EXPECT_EQ(core.status().state, RunState::kEmpty);
}

TEST(ExperimentRun, PhysicsFaultFailsTheRunWithTheReport) {
  ModelCore core;
  experiment::Experiment e = Bend(2.0);
  e.name = "explode";
  e.overrides = {{"ecce_arm.biceps.max_isometric_force", {1e15}}};
  e.schedule = {{0.0, "biceps", 1.0}};
  try {
    core.RunExperiment(e, "ecce_arm.dae", ArmBytes());
    FAIL() << "a 1e15 N muscle did not fault";
  } catch (const RunFailed& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("explode"), std::string::npos) << what;
    EXPECT_NE(what.find("faulted at t ="), std::string::npos) << what;
  }
  EXPECT_EQ(core.status().state, RunState::kFaulted);
  // the Model takes the next experiment
  EXPECT_NO_THROW(core.RunExperiment(Bend(0.05), "ecce_arm.dae", ArmBytes()));
}

TEST(ExperimentRun, ExportedBytesLoadAgain) {
  ModelCore core;
  core.LoadData("ecce_arm.dae", ArmBytes());
  core.SetChannel("ecce_arm.forearm.mass", {0.77});
  const std::string exported = core.ExportBytes();
  ASSERT_GT(exported.size(), 1000u);
  ModelCore other;
  other.LoadData("tuned.dae", exported);
  // Bullet keeps masses in float
  EXPECT_NEAR(other.Sample({"ecce_arm.forearm.mass"})[0].values[0], 0.77, 1e-6);
  EXPECT_NE(other.status().scene.find("tuned.dae"), std::string::npos);
}

TEST(ExperimentRun, AnswersStatusMeanwhileAndStopEndsIt) {
  ModelCore core;
  const std::string arm = ArmBytes();
  experiment::Experiment e = Bend(1000.0);  // far longer than the test waits
  auto run = std::async(std::launch::async, [&] { return core.RunExperiment(e, "a.dae", arm); });
  // status answers while the run steps: it shows the run's progress, not its end
  Status s;
  for (int i = 0; i < 2000; ++i) {
    s = core.status();
    if (s.steps > 100) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(s.state, RunState::kRunning);
  EXPECT_GT(s.steps, 100u);
  EXPECT_LT(s.sim_time, 1000.0);
  // other control calls are refused; stop ends the run early and says so
  EXPECT_THROW(core.Start(), NotAvailable);
  EXPECT_THROW(core.SetChannel("ecce_arm.forearm.mass", {2.0}), NotAvailable);
  core.Stop();
  try {
    run.get();
    FAIL() << "the run went on after stop";
  } catch (const NotAvailable& error) {
    EXPECT_NE(std::string(error.what()).find("a stop request ended it early"), std::string::npos)
        << error.what();
  }
  // the Model takes the next one
  EXPECT_NO_THROW(core.RunExperiment(Bend(0.05), "ecce_arm.dae", arm));
}

TEST(ExperimentRun, ZaeArchiveLoadsByContent) {
  CALIPER_REQUIRE_CORPUS();
  const std::string zae =
      ReadFile(caliper::testing::CorpusDir() + "/collada/collada_robots/barrett-hand.zae");
  ASSERT_GT(zae.size(), 1000u);
  ModelCore core;
  core.LoadData("barrett-hand.zae", zae);
  ASSERT_NE(core.description(), nullptr);
  EXPECT_GT(core.description()->bodies.size(), 3u);
  EXPECT_EQ(core.status().state, RunState::kStopped);
  // a .zae named .dae is read as XML and fails with the name given
  try {
    core.LoadData("hand.dae", zae);
    FAIL() << "a zip archive loaded as .dae";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("hand.dae"), std::string::npos) << e.what();
  }
  EXPECT_NE(core.status().scene.find("barrett-hand.zae"), std::string::npos);
}

}  // namespace
}  // namespace caliper::simulation
