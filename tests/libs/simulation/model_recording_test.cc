// Session recordings on ModelCore, without CORBA: a session with commands, parameter writes, a
// pull and a scene edit recorded; replayed, it gives every keyframe again bit for bit and the
// recorded channels equal; seeking back and forth lands on the same states; a fork from a middle
// keyframe goes on as the uninterrupted run did; a damaged scene version is refused saying so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>
#include <fstream>
#include <iterator>
#include <sqlite3.h>
#include <vector>

#include "caliper/core/scratch_directory.h"
#include "caliper/recording/recording.h"
#include "caliper/sgal/edits.h"
#include "caliper/simulation/model_core.h"

namespace caliper::simulation {
namespace {

std::string Model(const std::string& file) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/models/" + file;
}

std::vector<double> Read(ModelCore& core, const std::string& id) {
  return core.Sample({id}).at(0).values;
}

constexpr const char* kHand = "ecce_arm.hand.position";
constexpr const char* kTension = "ecce_arm.elbow_flexor.tendon.tension";

// 1.2 s of the arm: motors driven and changed, a command delay lengthened and shortened live, a
// tuned stiffness, a pull and its release, a via point moved; the hand's position at every step
// of the run
struct Session {
  std::vector<std::vector<double>> hand;  // after each step from the recording's start
  std::vector<double> hand_at_599;
};

Session RecordSession(ModelCore& core, const std::string& file) {
  Session s;
  core.Load(Model("ecce_arm.dae"));
  core.StepNow(37);  // the recording starts between keyframes
  ModelCore::RecordOptions options;
  options.keyframe_every = 100;
  options.channels = {kHand, kTension};
  core.StartRecording(file, options);
  auto run = [&](int n) {
    for (int i = 0; i < n; ++i) {
      core.StepNow(1);
      s.hand.push_back(Read(core, kHand));
    }
  };
  core.SetCommands({{"elbow_flexor", 6.0}});
  run(120);
  // a command delay lengthened live with commands in flight (the motor's state grows with it),
  // carried through the edit below, and shortened after it
  core.SetChannel("ecce_arm.elbow_flexor.command_delay", {0.08});
  core.SetCommands({{"elbow_flexor", 5.0}});
  run(30);
  core.SetChannel("ecce_arm.elbow_flexor.stiffness", {4000});
  core.SetCommands({{"shoulder_flexor", 4.0}, {"elbow_flexor", 2.0}});
  run(200);
  const auto hand = Read(core, kHand);
  core.Pull("hand", Eigen::Vector3d::Zero(), {hand[0] + 0.2, hand[1], hand[2] + 0.1}, 0);
  run(63);
  // an edit while the pull holds: the pull goes on in the edited scene
  core.Edit([&](const sgal::Scene& sc) { return sgal::SetMass(sc, "forearm", 1.2); });
  EXPECT_EQ(Read(core, "ecce_arm.elbow_flexor.command_delay"), std::vector<double>{0.08})
      << "the edit kept the delay set live";
  run(87);
  core.ReleasePull();
  core.SetChannel("ecce_arm.elbow_flexor.command_delay", {0.015});
  run(62);
  s.hand_at_599 = Read(core, kHand);
  run(1);  // step 600 of the session (37 + 563)
  sgal::PathElement via;
  via.body = "upper_arm";
  via.position = {0.02, 0, -0.1};
  core.Edit([&](const sgal::Scene& sc) { return sgal::InsertPathPoint(sc, "elbow_flexor", 1, via); });
  // undone and redone at the same step while paused: three keyframes at step 600, the last kept
  core.Undo();
  core.Redo();
  run(400);
  const auto stopped = core.StopRecording();
  EXPECT_GT(stopped.bytes, 100000u);  // the scene's 0.2 MB at least
  EXPECT_EQ(stopped.steps, 963u);
  return s;
}

class ModelRecording : public ::testing::Test {
 protected:
  core::ScratchDirectory dir_{"model-recording"};
  std::string file_ = dir_.path() + "/session.calrec";
};

TEST_F(ModelRecording, ReplayGivesEveryKeyframeAndChannelBackBitForBit) {
  ModelCore live;
  const Session session = RecordSession(live, file_);
  recording::Reader reader(file_);
  EXPECT_EQ(reader.header().first_step, 37u);
  EXPECT_EQ(reader.last_step(), 37u + 963u);
  const auto keyframes = reader.keyframe_steps();
  ASSERT_GE(keyframes.size(), 10u);  // 37, 100, ..., 900 and the edit's
  const auto samples = reader.Samples(0, reader.last_step() + 1);
  ASSERT_EQ(samples.size(), 963u);

  ModelCore replay;
  auto status = replay.OpenReplay(file_);
  EXPECT_TRUE(status.replaying);
  EXPECT_EQ(status.step, 37u);
  // commands and edits are refused while replaying
  EXPECT_THROW(replay.SetCommands({{"elbow_flexor", 1.0}}), NotAvailable);
  size_t identical = 0, compared = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    replay.StepNow(1);
    const auto hand = Read(replay, kHand);
    EXPECT_EQ(hand, session.hand[i]) << "step " << samples[i].step;
    const std::vector<double> recorded(samples[i].values.begin(), samples[i].values.begin() + 3);
    EXPECT_EQ(hand, recorded) << "step " << samples[i].step;
    ++compared;
    if (hand == session.hand[i]) ++identical;
    if (HasFailure()) break;
  }
  EXPECT_EQ(identical, compared);
  // it pauses at its end
  EXPECT_EQ(replay.replay_status().step, reader.last_step());
}

TEST_F(ModelRecording, VerifyFindsItIdenticalAndNamesTheFirstDivergence) {
  ModelCore live;
  RecordSession(live, file_);
  uint64_t told = 0;
  const Verification v = VerifyRecording(file_, [&](uint64_t step, uint64_t) { told = step; });
  EXPECT_TRUE(v.identical) << v.detail;
  EXPECT_EQ(v.steps, 963u);
  EXPECT_EQ(v.keyframes, 8u);  // 100 ... 900 but 600, where the edit's keyframe restarts the replay
  // (the edit at step 450 takes no periodic keyframe's place)
  EXPECT_EQ(v.samples, 963u);
  EXPECT_EQ(told, 1000u);
  // a keyframe changed in its last bit: the first divergence is named there
  recording::Reader reader(file_);
  recording::Keyframe k = reader.KeyframeAtOrBefore(500);
  ASSERT_EQ(k.step, 500u);
  k.state.engine[36 * 5 + 9] = std::nextafter(k.state.engine[36 * 5 + 9], 1e9);  // hand x
  const std::string bytes = recording::EncodeState(k.state);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file_.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* update = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "UPDATE keyframes SET state = ? WHERE step = 500", -1, &update,
                               nullptr),
            SQLITE_OK);
  sqlite3_bind_blob(update, 1, bytes.data(), static_cast<int>(bytes.size()), SQLITE_TRANSIENT);
  EXPECT_EQ(sqlite3_step(update), SQLITE_DONE);
  sqlite3_finalize(update);
  sqlite3_close(db);
  const Verification damaged = VerifyRecording(file_);
  EXPECT_FALSE(damaged.identical);
  EXPECT_EQ(damaged.divergent_step, 500u);
  EXPECT_NE(damaged.detail.find("body 'hand' position"), std::string::npos) << damaged.detail;
}

TEST_F(ModelRecording, SeekingBackAndForthLandsOnTheRecordedStates) {
  ModelCore live;
  const Session session = RecordSession(live, file_);
  ModelCore replay;
  const auto opened = replay.OpenReplay(file_);
  const double dt = 0.001;
  // (at step 600 the edit took place: seeking there gives the state after it)
  // 500: after the edit at 450 with the pull still held
  for (const uint64_t step : {650u, 120u, 999u, 599u, 38u, 601u, 500u, 599u}) {
    const auto status = replay.Seek(opened.start_time + (step - 37) * dt);
    ASSERT_EQ(status.step, step);
    EXPECT_EQ(Read(replay, kHand), session.hand[step - 38]) << "after seeking to step " << step;
  }
  EXPECT_EQ(Read(replay, kHand), session.hand_at_599);
}

TEST_F(ModelRecording, AForkFromAMiddleKeyframeGoesOnAsTheUninterruptedRun) {
  ModelCore live;
  const Session session = RecordSession(live, file_);
  ModelCore fork;
  const auto opened = fork.OpenReplay(file_);
  fork.Seek(opened.start_time + (300 - 37) * 0.001);  // a keyframe in the middle
  fork.Fork();
  EXPECT_FALSE(fork.replay_status().replaying);
  // no event from here until the pull at step 387: the fork goes on as the live run did
  fork.StepNow(80);
  EXPECT_EQ(Read(fork, kHand), session.hand[380 - 38]);
  // and after the fork the Model takes commands again
  EXPECT_NO_THROW(fork.SetCommands({{"elbow_flexor", 1.0}}));
}

// balls dropped onto a floor and onto each other: contacts that last across keyframes
sgal::Scene Balls() {
  sgal::Scene s;
  s.name = "balls";
  s.settings.time_step = 0.001;
  sgal::Body floor;
  floor.name = "floor";
  floor.type = sgal::BodyType::kStatic;
  floor.shapes.push_back({"plane", sgal::Plane{}, {}});
  s.bodies.push_back(floor);
  for (int i = 0; i < 5; ++i) {
    sgal::Body b;
    b.name = "ball" + std::to_string(i);
    b.pose.position = {0.03 * (i % 2), 0.02 * i, 0.06 + 0.11 * i};
    b.inertia.mass = 0.2;
    b.inertia.tensor = Eigen::Matrix3d::Identity() * (0.4 * 0.2 * 0.05 * 0.05);
    b.shapes.push_back({"ball", sgal::Sphere{0.05}, {}});
    s.bodies.push_back(b);
  }
  return s;
}

TEST_F(ModelRecording, AForkWithContactsGoesOnBitForBitPastLaterKeyframes) {
  ModelCore live;
  live.LoadScene(Balls(), "balls");
  live.StartRecording(file_, {});
  live.StepNow(700);
  const auto top = Read(live, "balls.ball4.position");
  live.StopRecording();
  ModelCore fork;
  const auto opened = fork.OpenReplay(file_);
  fork.Seek(opened.start_time + 0.2);  // the keyframe at step 200
  fork.Fork();
  fork.StepNow(500);  // past the keyframes at 300 ... 600, as the recorded run reset them
  EXPECT_EQ(Read(fork, "balls.ball4.position"), top);
  EXPECT_LT(top[2], 0.5) << "the balls did not come to rest on each other";
}

// what the Scene Renderer receives (the observer's snapshots) during a replay is the recording
class Snapshots : public CoreListener {
 public:
  void OnScene(std::shared_ptr<const sgal::Scene>, uint64_t) override {}
  void OnSnapshot(std::shared_ptr<const Snapshot> s) override { last = s; }
  void OnCleared() override {}
  std::shared_ptr<const Snapshot> last;
};

TEST_F(ModelRecording, ObserversOfAReplaySeeTheRecordedPoses) {
  ModelCore live;
  const Session session = RecordSession(live, file_);
  ModelCore replay;
  replay.OpenReplay(file_);
  Snapshots observer;
  replay.AddListener(&observer);
  const int hand = replay.description()->BodyIndex("hand");
  for (uint64_t step = 38; step <= 1000; step += 137) {
    replay.StepNow(step - replay.replay_status().step);
    ASSERT_TRUE(observer.last);
    EXPECT_EQ(observer.last->step, step);
    const Eigen::Vector3d p = observer.last->bodies.at(hand).pose.position;
    EXPECT_EQ(std::vector<double>({p.x(), p.y(), p.z()}), session.hand[step - 38]) << step;
  }
  replay.RemoveListener(&observer);
}

TEST_F(ModelRecording, AChangedSceneVersionIsRefusedSayingSo) {
  ModelCore live;
  RecordSession(live, file_);
  // the recording's scene replaced by another model's (a file edited behind its back): its
  // keyframes do not fit it
  std::ifstream in(Model("pendulum_tendon.dae"), std::ios::binary);
  const std::string other((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file_.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* update = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "UPDATE scenes SET data = ? WHERE version = 0", -1, &update,
                               nullptr),
            SQLITE_OK);
  sqlite3_bind_blob(update, 1, other.data(), static_cast<int>(other.size()), SQLITE_TRANSIENT);
  EXPECT_EQ(sqlite3_step(update), SQLITE_DONE);
  sqlite3_finalize(update);
  sqlite3_close(db);
  ModelCore replay;
  try {
    replay.OpenReplay(file_);
    ADD_FAILURE() << "a recording whose scene changed was replayed";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(file_), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not fit its scene"), std::string::npos) << e.what();
  }
  // recorded by another engine build: refused before anything is replayed
  ModelCore live2;
  const std::string other_file = dir_.path() + "/other_engine.caliper";
  RecordSession(live2, other_file);
  ASSERT_EQ(sqlite3_open(other_file.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE meta SET value = 'bullet 2.89 double, state layout 1' "
                             "WHERE key = 'engine'",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  try {
    replay.OpenReplay(other_file);
    ADD_FAILURE() << "a recording of another engine was replayed";
  } catch (const recording::RecordingError& e) {
    EXPECT_NE(std::string(e.what()).find("was recorded with bullet 2.89 double"), std::string::npos)
        << e.what();
  }
}

TEST_F(ModelRecording, WithoutChannelsTheRecordingStillEndsWhereItStopped) {
  ModelCore core;
  core.Load(Model("ecce_arm.dae"));
  core.StartRecording(file_, {});
  core.SetCommands({{"elbow_flexor", 5.0}});
  core.StepNow(550);  // the last keyframe is at 500
  core.StopRecording();
  const auto hand = Read(core, kHand);
  recording::Reader reader(file_);
  EXPECT_EQ(reader.last_step(), 550u);
  ModelCore replay;
  replay.OpenReplay(file_);
  replay.Start();  // plays as fast as the real-time factor allows, and pauses at the end
  replay.SetRealTimeFactor(0);
  for (int i = 0; i < 200 && replay.replay_status().step < 550; ++i)
    replay.Advance(std::chrono::milliseconds(5));
  EXPECT_EQ(replay.replay_status().step, 550u);
  EXPECT_EQ(replay.status().state, RunState::kPaused);
  EXPECT_EQ(Read(replay, kHand), hand);
  // a step request ends at the recording's end too, with the steps it ran
  replay.Seek(0.5);
  EXPECT_EQ(replay.StepNow(200), 50u);
  EXPECT_EQ(replay.replay_status().step, 550u);
  EXPECT_EQ(replay.StepNow(10), 0u);
  EXPECT_EQ(Read(replay, kHand), hand);
}

TEST_F(ModelRecording, TheLogGoesIntoTheRecording) {
  ModelCore core;
  core.Load(Model("ecce_arm.dae"));
  core.StartRecording(file_, {});
  core.StepNow(10);
  core.Edit([](const sgal::Scene& s) { return sgal::SetMass(s, "hand", 0.4); });  // logs a notice
  // a record of another component, as the Logging component hands them to the Model's listener
  core.UseSessionLog(true);
  core.AddSessionLog({1.7e9, "WARN", "caliper.renderer.renderer", "renderer0", "a renderer's word"});
  core.StopRecording();
  recording::Reader reader(file_);
  bool own = false, other = false;
  for (const auto& r : reader.Log()) {
    own |= r.message.find("scene edit: set the mass of hand to 0.4 kg") != std::string::npos;
    other |= r.component == "renderer0" && r.message == "a renderer's word";
  }
  EXPECT_TRUE(own) << "the Model's own record of the edit";
  EXPECT_TRUE(other) << "another component's record";
}

TEST_F(ModelRecording, BoundsAClientOrAFileCannotLift) {
  ModelCore core;
  core.Load(Model("ecce_arm.dae"));
  ModelCore::RecordOptions wide;
  wide.keyframe_every = 1001;  // a seek would re-simulate that much holding the Model
  EXPECT_THROW(core.StartRecording(file_, wide), InvalidValue);
  ModelCore::RecordOptions huge;
  huge.max_bytes = Limits{}.recording_bytes + 1;
  EXPECT_THROW(core.StartRecording(file_, huge), InvalidValue);
  // a file whose time step or keyframe interval would divide by zero or step without end
  core.StartRecording(file_, {});
  core.StepNow(50);
  core.StopRecording();
  for (const char* sql : {"UPDATE meta SET value = '0' WHERE key = 'time_step_s'",
                          "UPDATE meta SET value = 'nan' WHERE key = 'time_step_s'",
                          "UPDATE meta SET value = '0' WHERE key = 'keyframe_every'"}) {
    const std::string copy = dir_.path() + "/bad" + std::to_string(std::hash<std::string>{}(sql));
    std::ifstream in(file_, std::ios::binary);
    std::ofstream(copy, std::ios::binary) << in.rdbuf();
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(copy.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
    ModelCore replay;
    EXPECT_THROW(replay.OpenReplay(copy), recording::RecordingError) << sql;
  }
}

TEST_F(ModelRecording, AFullDiskEndsTheRecordingAndTheSimulationGoesOn) {
  ModelCore core;
  core.Load(Model("ecce_arm.dae"));
  ModelCore::RecordOptions options;
  options.channels = {kHand, kTension};
  options.max_bytes = 1024 * 1024;  // the scene's 0.2 MB and some seconds of samples
  core.StartRecording(file_, options);
  for (int i = 0; i < 40 && core.recording_status().recording; ++i) {
    core.StepNow(500);
    std::this_thread::sleep_for(std::chrono::milliseconds(120));  // commits
  }
  const auto status = core.recording_status();
  EXPECT_FALSE(status.recording);
  EXPECT_NE(status.error.find("full"), std::string::npos) << status.error;
  EXPECT_EQ(core.StepNow(100), 100u);  // the simulation goes on
  EXPECT_EQ(core.status().state, RunState::kPaused);
  recording::Reader reader(file_);  // what was committed opens
  EXPECT_GT(reader.last_step(), 0u);
}

}  // namespace
}  // namespace caliper::simulation
