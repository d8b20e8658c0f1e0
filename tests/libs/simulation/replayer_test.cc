// A session recording replayed on its own: written with SessionRecorder from a pendulum run with
// a command, a parameter write, a pull and its release, then re-simulated from its first and from
// a middle keyframe bit for bit; each scene version imported once; the keyframe hook, an edit,
// the seek's step, and the files a replay refuses, with their messages.
#include "caliper/simulation/replayer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "caliper/core/scratch_directory.h"
#include "caliper/model_file/model_file.h"
#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/recording/recording.h"
#include "caliper/simulation/session_recorder.h"

namespace caliper::simulation {
namespace {

using ::testing::HasSubstr;
using ::testing::StrEq;
using ::testing::ThrowsMessage;

std::string Model(const std::string& file) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/models/" + file;
}

sgal::Scene Import(const std::string& file) {
  std::vector<std::string> warnings;
  return model_file::Import(Model(file), &warnings);
}

constexpr uint64_t kSteps = 20;

/// A recording of the pendulum (keyframes every 5 steps) with a command at step 3, a write of the
/// fake parameter `m.gain` at step 4, a pull from step 6 released at step 12, and the engine's
/// state at its end; an importer that counts its calls.
struct ReplayerTest : ::testing::Test {
  ReplayerTest() {
    path = scratch.path() + "/session.calrec";
    header.model_name = "pendulum";
    header.scene_file_name = "pendulum.dae";
    header.keyframe_every = 5;
    header.engine = physics_bullet::EngineId();
  }

  /// A registry with the writable fake channel `m.gain`, whose writes land in `gains`.
  void AddGain(daq::Registry& registry) {
    registry.Add(
        {"m.gain", "", daq::Shape::Scalar(), false, false, "a fake parameter"},
        [](double* out) { out[0] = 0; },
        [this](const double* values) { gains.push_back(values[0]); });
  }

  /// Runs the recorded session as the Model does: the boundary's events, a keyframe when due,
  /// the step. `edit_at`: an edit event at that step instead of nothing.
  void Record(uint64_t edit_at = UINT64_MAX) {
    auto physics = physics_bullet::MakeScene(Import("pendulum_tendon.dae"));
    header.time_step = physics->description().settings.time_step;
    daq::Registry registry;
    AddGain(registry);
    SessionRecorder recorder(path, header, {0, 0, "pendulum.dae", "<COLLADA/>"}, 0, registry);
    for (uint64_t step = 0; step < kSteps; ++step) {
      if (step == 3) {
        physics->SetCommand("motor", 0.5);
        recorder.AddEvent(step, "command", "motor", {0.5});
      } else if (step == 4) {
        registry.Set("m.gain", {2.0});
        recorder.AddEvent(step, "parameter", "m.gain", {2.0});
      } else if (step == 6) {
        sgal::Pull pull;
        pull.body = physics->description().BodyIndex("pendulum");
        pull.point = {0, 0, 0};
        pull.target = {0.3, 0.2, 0.1};
        pull.stiffness = 50;
        pull.damping = 3;
        physics->SetPull(pull);
        recorder.AddEvent(step, "pull", "pendulum", {0, 0, 0, 0.3, 0.2, 0.1, 50, 3});
      } else if (step == 12) {
        physics->ClearPull();
        recorder.AddEvent(step, "release", "", {});
      }
      if (step == edit_at) recorder.AddEvent(step, "edit", "a test edit", {});
      if (recorder.KeyframeDue(step)) recorder.AddKeyframe(*physics);
      physics->Step();
    }
    recorder.AddEvent(kSteps, "end", "stopped", {});
    end = physics->SaveDynamicState();
    gains.clear();
  }

  Replayer::Importer Importer(const std::string& file = "pendulum_tendon.dae") {
    return [this, file](const std::string& file_name, const std::string& bytes) {
      ++imports;
      EXPECT_EQ(file_name, "pendulum.dae");
      EXPECT_EQ(bytes, "<COLLADA/>");
      return Import(file);
    };
  }

  /// A file of one keyframe (the recording's end state) at step 0 and `events`, as a damaged or
  /// hand-made recording may be; its path.
  std::string WriteOneKeyframe(const std::string& suffix,
                               const std::vector<recording::Event>& events) {
    recording::Writer writer(path + suffix, header, {0, 0, "pendulum.dae", "<COLLADA/>"},
                             std::chrono::milliseconds(500), 0);
    recording::Keyframe k;
    k.state = end;
    writer.AddKeyframe(k);
    for (const auto& e : events) writer.AddEvent(e);
    return path + suffix;
  }

  /// Restores `replayer` at `step` into a new engine (in `physics`, its registry `registry`).
  void Restore(Replayer& replayer, uint64_t step) {
    const Replayer::Start start = replayer.StartAt(step, Importer());
    physics = physics_bullet::MakeScene(*start.scene);
    registry = std::make_unique<daq::Registry>();
    AddGain(*registry);
    replayer.Restore(start, *physics, *registry);
  }

  /// Steps as the Model does while replaying: the events due, then the step, up to `last`.
  void PlayTo(Replayer& replayer, uint64_t last) {
    while (physics->steps() < last) {
      ASSERT_EQ(replayer.BeforeStep(physics->steps(), *physics, *registry, commands),
                Replayer::Due::kApplied);
      physics->Step();
    }
  }

  core::ScratchDirectory scratch{"caliper-replayer-test"};
  std::string path;
  recording::Header header;
  sgal::DynamicState end;     // the recorded run's at its last step
  std::vector<double> gains;  // writes to m.gain, in order
  int imports = 0;            // calls of Importer()'s importer
  std::unique_ptr<sgal::PhysicsScene> physics;
  std::unique_ptr<daq::Registry> registry;
  std::map<std::string, double> commands;
};

TEST_F(ReplayerTest, ReplaysTheRunFromItsStartBitForBit) {
  Record();
  Replayer replayer(path);
  EXPECT_EQ(replayer.first_step(), 0u);
  EXPECT_EQ(replayer.last_step(), kSteps);
  EXPECT_EQ(replayer.keyframe_every(), 5u);
  Restore(replayer, replayer.first_step());
  EXPECT_EQ(replayer.next_event(), 1u);  // just after the mark of the keyframe at step 0
  EXPECT_TRUE(gains.empty());
  PlayTo(replayer, kSteps);
  EXPECT_EQ(gains, (std::vector<double>{2.0}));
  EXPECT_EQ(commands, (std::map<std::string, double>{{"motor", 0.5}}));
  const sgal::DynamicState got = physics->SaveDynamicState();
  EXPECT_EQ(got.time, end.time);
  EXPECT_EQ(got.engine, end.engine);
  EXPECT_EQ(got.commands, end.commands);
  EXPECT_EQ(got.actuators, end.actuators);
}

TEST_F(ReplayerTest, RestoresAMiddleKeyframeWithTheWritesAndThePullInForce) {
  Record();
  Replayer replayer(path);
  Restore(replayer, 9);  // the keyframe at step 5: after the write, before the pull
  EXPECT_EQ(physics->steps(), 5u);
  EXPECT_EQ(gains, (std::vector<double>{2.0}));  // not in a keyframe: written again
  // the keyframe at step 10, the pull in force
  Restore(replayer, 11);
  EXPECT_EQ(physics->steps(), 10u);
  PlayTo(replayer, kSteps);
  EXPECT_EQ(physics->SaveDynamicState().engine, end.engine);
  EXPECT_TRUE(commands.empty());  // the command came before: it is in the keyframe
}

TEST_F(ReplayerTest, ImportsEachSceneVersionOnce) {
  Record();
  Replayer replayer(path);
  const Replayer::Start a = replayer.StartAt(0, Importer());
  const Replayer::Start b = replayer.StartAt(17, Importer());
  EXPECT_EQ(imports, 1);
  EXPECT_EQ(a.scene, b.scene);
  EXPECT_EQ(a.keyframe.step, 0u);
  EXPECT_EQ(b.keyframe.step, 15u);
  EXPECT_EQ(b.scene_step, 0u);
}

TEST_F(ReplayerTest, TellsTheHookEachKeyframeWithTheEngineThere) {
  Record();
  Replayer replayer(path);
  std::vector<uint64_t> at;
  replayer.set_keyframe_hook([&](uint64_t step, const sgal::PhysicsScene& engine) {
    at.push_back(step);
    EXPECT_EQ(engine.steps(), step);
  });
  Restore(replayer, 0);
  PlayTo(replayer, kSteps);
  EXPECT_EQ(at, (std::vector<uint64_t>{5, 10, 15}));  // the restored keyframe's mark is passed
}

TEST_F(ReplayerTest, StopsAtAnEditForItsOwnerToRestore) {
  Record(/*edit_at=*/7);
  Replayer replayer(path);
  Restore(replayer, 0);
  PlayTo(replayer, 7);
  const size_t next = replayer.next_event();
  EXPECT_EQ(replayer.BeforeStep(7, *physics, *registry, commands), Replayer::Due::kEdit);
  EXPECT_EQ(replayer.next_event(), next);  // the edit is not passed: a restore moves on
}

TEST_F(ReplayerTest, FindsTheStepNearestATimeClampedToTheRecording) {
  Record();
  Replayer replayer(path);
  const double dt = header.time_step, start = replayer.start_time();
  EXPECT_EQ(start, 0.0);
  EXPECT_DOUBLE_EQ(replayer.end_time(), kSteps * dt);
  EXPECT_EQ(replayer.StepNearest(-1), 0u);
  EXPECT_EQ(replayer.StepNearest(1e9), kSteps);
  EXPECT_EQ(replayer.StepNearest(start + 7.4 * dt), 7u);
  EXPECT_EQ(replayer.StepNearest(start + 7.6 * dt), 8u);
  EXPECT_EQ(replayer.KeyframeStepAtOrBefore(14), 10u);
}

TEST_F(ReplayerTest, RefusesKeyframesTooFarApart) {
  Record();
  // a last event far beyond the only keyframe
  const std::string far =
      WriteOneKeyframe(".far", {{0, "keyframe", "", {}}, {1500, "end", "stopped", {}}});
  EXPECT_THAT([&] { Replayer replayer(far); },
              ThrowsMessage<recording::RecordingError>(
                  StrEq(far + ": its keyframes lie up to 1500 steps apart; a replay takes at "
                              "most 1000")));
}

TEST_F(ReplayerTest, RefusesARecordingOfAnotherEngine) {
  header.engine = "another-engine 9";
  Record();
  EXPECT_THAT([&] { Replayer replayer(path); },
              ThrowsMessage<recording::RecordingError>(
                  HasSubstr(path + " was recorded with another-engine 9; this build runs ")));
}

TEST_F(ReplayerTest, RefusesAKeyframeThatDoesNotFitTheScene) {
  Record();
  Replayer replayer(path);
  const Replayer::Start start = replayer.StartAt(0, Importer("two_link_antagonistic.dae"));
  physics = physics_bullet::MakeScene(*start.scene);
  daq::Registry other;
  EXPECT_THAT([&] { replayer.Restore(start, *physics, other); },
              ThrowsMessage<recording::RecordingError>(
                  HasSubstr(path + ": the keyframe at step 0 does not fit its scene")));
}

TEST_F(ReplayerTest, RefusesAKeyframeWithoutItsMarkAsDamaged) {
  Record();
  const std::string damaged = WriteOneKeyframe(".damaged", {});  // and no "keyframe" event
  Replayer replayer(damaged);
  const Replayer::Start start = replayer.StartAt(0, Importer());
  physics = physics_bullet::MakeScene(*start.scene);
  daq::Registry empty;
  EXPECT_THAT([&] { replayer.Restore(start, *physics, empty); },
              ThrowsMessage<recording::RecordingError>(
                  StrEq(damaged + ": the keyframe at step 0 has no mark among the events (a "
                                  "damaged file)")));
}

}  // namespace
}  // namespace caliper::simulation
