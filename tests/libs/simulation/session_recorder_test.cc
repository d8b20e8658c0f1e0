// A session recording written on its own and read back: keyframes where they are due with their
// marks among the events, channel samples every N steps from the first step, a channel that
// vanished recorded as NaN, and a new scene version named by the keyframes after it.
#include "caliper/simulation/session_recorder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "caliper/core/scratch_directory.h"
#include "caliper/model_file/model_file.h"
#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::simulation {
namespace {

std::string Model(const std::string& file) {
  const char* src = std::getenv("CALIPER_SOURCE_DIR");
  return std::string(src ? src : ".") + "/models/" + file;
}

/// The pendulum's engine, a registry of two fake channels that follow its step count
/// (`m.x` = step, `m.v` = (step, 2 step, 3 step)), and a recording of both every 2 steps with
/// keyframes every 5.
struct SessionRecorderTest : ::testing::Test {
  SessionRecorderTest() {
    std::vector<std::string> warnings;
    physics =
        physics_bullet::MakeScene(model_file::Import(Model("pendulum_tendon.dae"), &warnings));
    registry.Add({"m.x", "m", daq::Shape::Scalar(), false, false, "the step"},
                 [this](double* out) { out[0] = static_cast<double>(physics->steps()); });
    registry.Add({"m.v", "m/s", daq::Shape::Vector(3), false, false, "multiples of the step"},
                 [this](double* out) {
                   for (int i = 0; i < 3; ++i)
                     out[i] = static_cast<double>((i + 1) * physics->steps());
                 });
    header.model_name = "pendulum";
    header.scene_file_name = "pendulum.dae";
    header.time_step = physics->description().settings.time_step;
    header.keyframe_every = 5;
    header.channels_every = 2;
    header.channels = {{"m.x", "m", 1, 1}, {"m.v", "m/s", 3, 1}};
    header.first_step = 0;
    path = scratch.path() + "/session.calrec";
    recorder = std::make_unique<SessionRecorder>(path, header, Scene(0), 0, registry);
  }

  recording::SceneVersion Scene(uint32_t version) {
    return {version, physics->steps(), "pendulum.dae", "<COLLADA/>"};
  }

  /// Steps `n` times as the Model does: a keyframe when due, the step, the sample.
  void Run(int n) {
    for (int k = 0; k < n; ++k) {
      if (recorder->KeyframeDue(physics->steps())) recorder->AddKeyframe(*physics);
      physics->Step();
      recorder->AfterStep(physics->steps(), physics->time());
    }
  }

  /// Ends the recording (commits) and opens it.
  std::unique_ptr<recording::Reader> Read() {
    recorder.reset();
    return std::make_unique<recording::Reader>(path);
  }

  core::ScratchDirectory scratch{"caliper-session-recorder-test"};
  std::unique_ptr<sgal::PhysicsScene> physics;
  daq::Registry registry;
  recording::Header header;
  std::string path;
  std::unique_ptr<SessionRecorder> recorder;
};

TEST_F(SessionRecorderTest, KeyframesWhereDueWithTheirMarks) {
  EXPECT_EQ(recorder->values(), 4u);
  EXPECT_TRUE(recorder->KeyframeDue(0));
  recorder->AddKeyframe(*physics);
  EXPECT_FALSE(recorder->KeyframeDue(0));  // taken there already
  EXPECT_FALSE(recorder->KeyframeDue(3));
  EXPECT_TRUE(recorder->KeyframeDue(10));
  Run(3);
  recorder->AddEvent(physics->steps(), "command", "motor", {0.5});
  Run(8);
  const auto reader = Read();
  EXPECT_EQ(reader->keyframe_steps(), (std::vector<uint64_t>{0, 5, 10}));
  std::vector<std::string> events;
  for (const auto& e : reader->Events(0, 100))
    events.push_back(std::to_string(e.step) + " " + e.kind + (e.target.empty() ? "" : " ") +
                     e.target);
  EXPECT_EQ(events, (std::vector<std::string>{"0 keyframe", "3 command motor", "5 keyframe",
                                              "10 keyframe"}));
  EXPECT_EQ(reader->KeyframeAtOrBefore(7).state.steps, 5u);
}

TEST_F(SessionRecorderTest, SamplesEveryNStepsFromTheFirst) {
  recorder->AddKeyframe(*physics);
  Run(7);
  const auto reader = Read();
  const std::vector<recording::Sample> samples = reader->Samples(0, 100);
  ASSERT_EQ(samples.size(), 3u);  // steps 2, 4, 6
  for (size_t i = 0; i < samples.size(); ++i) {
    const double step = 2.0 * static_cast<double>(i + 1);
    EXPECT_EQ(samples[i].step, static_cast<uint64_t>(step));
    EXPECT_EQ(samples[i].values, (std::vector<double>{step, step, 2 * step, 3 * step}));
  }
}

TEST_F(SessionRecorderTest, RecordsAVanishedChannelAsNaN) {
  recorder->AddKeyframe(*physics);
  Run(2);
  registry.Remove("m.x");
  recorder->ResolveChannels();
  EXPECT_EQ(recorder->values(), 4u);  // the layout stays
  Run(2);
  const auto reader = Read();
  const std::vector<recording::Sample> samples = reader->Samples(0, 100);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].values[0], 2.0);
  EXPECT_TRUE(std::isnan(samples[1].values[0]));
  EXPECT_EQ(samples[1].values[3], 12.0);  // m.v read on, through its handle resolved anew
}

TEST_F(SessionRecorderTest, KeyframesAfterANewSceneNameIt) {
  recorder->AddKeyframe(*physics);
  Run(2);
  EXPECT_EQ(recorder->scene_version(), 0u);
  recorder->AddScene(physics->steps(), "pendulum.dae", "<COLLADA version=\"edited\"/>");
  EXPECT_EQ(recorder->scene_version(), 1u);
  recorder->AddKeyframe(*physics);
  const auto reader = Read();
  const std::vector<recording::SceneVersion> scenes = reader->scenes();
  ASSERT_EQ(scenes.size(), 2u);
  EXPECT_EQ(scenes[1].version, 1u);
  EXPECT_EQ(scenes[1].step, 2u);
  EXPECT_EQ(reader->KeyframeAtOrBefore(0).scene_version, 0u);
  EXPECT_EQ(reader->KeyframeAtOrBefore(2).scene_version, 1u);
}

}  // namespace
}  // namespace caliper::simulation
