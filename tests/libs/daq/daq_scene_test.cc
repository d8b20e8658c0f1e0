// A Bullet pendulum's quantities as DAQ channels: the ids, units and shapes registered, values
// that agree with the scene, one BodyStates() fetch per sampled step, writes that reach the
// scene, and a recorder following the pendulum through a scene reload.
#include "caliper/daq/daq_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "caliper/daq/recorder.h"
#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::daq {
namespace {

using Eigen::Vector3d;

/// A 1 kg ball on a 0.5 m rod hinged to the world about y (`pivot`), with a cord from a world
/// point to the ball driven by a DC motor (`motor`, default parameters, 0 V).
sgal::Scene Pendulum(const std::string& hinge_name = "pivot") {
  sgal::Scene s;
  s.name = "pendulum";
  sgal::Body bob;
  bob.name = "bob";
  bob.pose.position = Vector3d(0.5 * std::sin(0.3), 0, -0.5 * std::cos(0.3));
  bob.inertia.mass = 1.0;
  bob.inertia.tensor = Eigen::Matrix3d::Identity() * 1.6e-4;
  bob.shapes.push_back({"ball", sgal::Sphere{0.02}, {}});
  s.bodies.push_back(bob);
  sgal::Constraint hinge;
  hinge.name = hinge_name;
  hinge.body_a = "bob";
  const Eigen::Quaterniond z_to_y(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()));
  hinge.frame_a.position = -bob.pose.position;
  hinge.frame_a.orientation = z_to_y;
  hinge.frame_b.orientation = z_to_y;
  s.constraints.push_back(hinge);
  sgal::Tendon cord;
  cord.name = "cord";
  sgal::PathElement anchor;
  anchor.position = Vector3d(-0.5, 0, -0.5);
  sgal::PathElement end;
  end.body = "bob";
  cord.path = {anchor, end};
  cord.collide_with_bodies = false;
  s.tendons.push_back(cord);
  s.actuators.push_back({"motor", "dc_motor_tendon", "cord", {}, {}});
  return s;
}

/// Expects `f` to throw E whose message contains `part`.
template <typename E, typename F>
void ExpectThrowsWith(F f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no exception, expected one containing '" << part << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
        << "message '" << e.what() << "' lacks '" << part << "'";
  }
}

struct Fixture : ::testing::Test {
  Fixture() : scene(physics_bullet::MakeScene(Pendulum())) {
    channels = RegisterScene(registry, "pend", *scene);
  }
  void Step(int n) {
    for (int i = 0; i < n; ++i) {
      scene->Step();
      channels.sampler->Refresh();
    }
  }

  std::unique_ptr<sgal::PhysicsScene> scene;
  Registry registry;
  SceneChannels channels;
};

TEST_F(Fixture, RegistersEveryParameterAndTheBodyQuantities) {
  EXPECT_TRUE(channels.skipped.empty());
  EXPECT_EQ(channels.ids.size(), registry.size());
  const auto parameters = scene->Parameters();
  EXPECT_EQ(registry.size(), parameters.size() + 5) << "5 channels for the one body";
  for (const auto& p : parameters) {
    const ChannelInfo& info = registry.Info("pend." + p.id);
    EXPECT_EQ(info.unit, p.unit) << p.id;
    EXPECT_EQ(info.shape, Shape::Scalar()) << p.id;
    EXPECT_EQ(info.writable, p.writable) << p.id;
    EXPECT_EQ(info.is_static, p.is_static) << p.id;
    EXPECT_FALSE(info.description.empty());
  }
  EXPECT_EQ(registry.Info("pend.motor.current").unit, "A");
  EXPECT_EQ(registry.Info("pend.cord.tendon.tension").unit, "N");
  EXPECT_EQ(registry.Info("pend.pivot.position").unit, "rad");
  EXPECT_TRUE(registry.Info("pend.bob.mass").is_static);

  const auto body = registry.List("pend.bob.*");
  std::vector<std::string> ids;
  for (const auto& c : body) ids.push_back(c.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"pend.bob.angular_velocity", "pend.bob.linear_velocity",
                                           "pend.bob.mass", "pend.bob.orientation",
                                           "pend.bob.position", "pend.bob.rotation"}));
  EXPECT_EQ(registry.Info("pend.bob.position").shape, Shape::Vector(3));
  EXPECT_EQ(registry.Info("pend.bob.position").unit, "m");
  EXPECT_EQ(registry.Info("pend.bob.orientation").shape, Shape::Vector(4));
  EXPECT_EQ(registry.Info("pend.bob.rotation").shape, Shape::Matrix(3, 3));
  EXPECT_EQ(registry.Info("pend.bob.linear_velocity").unit, "m/s");
  EXPECT_EQ(registry.Info("pend.bob.angular_velocity").unit, "rad/s");
  EXPECT_FALSE(registry.Info("pend.bob.position").writable);
  EXPECT_FALSE(registry.Info("pend.bob.position").is_static);
  EXPECT_EQ(registry.List("pend.*.tension").size(), 2u);  // cord.tendon.tension, motor.tension
}

TEST_F(Fixture, ValuesAgreeWithTheScene) {
  Step(300);
  const sgal::BodyState state = scene->BodyStates()[0];
  const auto r =
      registry.Sample({"pend.bob.position", "pend.bob.orientation", "pend.bob.rotation",
                       "pend.bob.linear_velocity", "pend.bob.angular_velocity",
                       "pend.pivot.position", "pend.cord.tendon.length", "pend.motor.current"});
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(r[0].values[i], state.pose.position[i]);
    EXPECT_EQ(r[3].values[i], state.linear_velocity[i]);
    EXPECT_EQ(r[4].values[i], state.angular_velocity[i]);
  }
  const Eigen::Quaterniond& q = state.pose.orientation;
  EXPECT_EQ(r[1].values, (std::vector<double>{q.w(), q.x(), q.y(), q.z()}));
  const Eigen::Matrix3d m = q.toRotationMatrix();
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col)
      EXPECT_NEAR(r[2].values[row * 3 + col], m(row, col), 1e-15) << "row-major";
  EXPECT_EQ(r[5].values[0], scene->GetParameter("pivot.position"));
  EXPECT_EQ(r[6].values[0], scene->GetParameter("cord.tendon.length"));
  EXPECT_EQ(r[7].values[0], scene->GetParameter("motor.current"));
  EXPECT_GT(std::abs(r[3].values[0]), 1e-3) << "the pendulum swings";
}

TEST_F(Fixture, FetchesBodyStatesOncePerSampledStep) {
  std::vector<Handle> handles;
  for (const auto& c : registry.List("pend.bob.*")) handles.push_back(registry.Resolve(c.id));
  double buffer[9];
  Step(1);
  for (int k = 0; k < 3; ++k)
    for (Handle h : handles) registry.Read(h, buffer);
  EXPECT_EQ(channels.sampler->fetches(), 1u);
  Step(10);  // nobody samples these
  EXPECT_EQ(channels.sampler->fetches(), 1u);
  registry.Read(handles[0], buffer);
  registry.Read(handles[1], buffer);
  EXPECT_EQ(channels.sampler->fetches(), 2u);
}

TEST_F(Fixture, ABodysChannelsAreReadInPlaceFromTheSampler) {
  // in channel order, next to each other: a recorder copies a body's five channels in one go
  const double* at = nullptr;
  for (const char* field :
       {"position", "orientation", "rotation", "linear_velocity", "angular_velocity"}) {
    const Access a = registry.Resolved(registry.Resolve(std::string("pend.bob.") + field));
    EXPECT_EQ(a.block, channels.sampler.get()) << field;
    if (at) {
      EXPECT_EQ(a.values, at) << field;
    }
    at = a.values + a.size;
  }
  EXPECT_EQ(at, channels.sampler->values(0) + SceneSampler::kValuesPerBody);
}

TEST(DaqScene, RecordsTendonsAtTheSameInstantAsTheBodies) {
  // sampled after Step(): the cord's length is the distance from its anchor to the bob where
  // the bob is now (a length from before the step would be one step's motion off)
  sgal::Scene taut = Pendulum();
  taut.actuators[0].parameters = {
      {"stiffness", 5000}, {"damping", 10}, {"rest_length", 0.1}, {"pretension", 9}};
  auto scene = physics_bullet::MakeScene(taut);
  Registry registry;
  const SceneChannels channels = RegisterScene(registry, "pend", *scene);
  Recorder recorder(registry);
  SubscriptionOptions options;
  options.ids = {"pend.bob.position", "pend.cord.tendon.length", "pend.cord.tendon.speed",
                 "pend.cord.tendon.tension"};
  options.batch_steps = 200;
  const SubscriptionId id = recorder.Subscribe(options);
  std::vector<sgal::TendonState> tendons;
  for (int i = 0; i < 200; ++i) {
    scene->Step();
    channels.sampler->Refresh();
    recorder.OnStep(scene->steps(), scene->time());
    tendons.push_back(scene->TendonStates()[0]);
  }
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 1u);
  const Batch& b = batches[0];
  const Vector3d anchor(-0.5, 0, -0.5);
  double largest_step_m = 0;
  for (size_t k = 0; k < b.step_count; ++k) {
    const double* v = b.data.data() + k * b.values_per_sample;
    const Vector3d bob(v[0], v[1], v[2]);
    EXPECT_NEAR(v[3], (bob - anchor).norm(), 1e-6) << "sample " << k;
    EXPECT_EQ(v[3], tendons[k].length) << "sample " << k;
    EXPECT_EQ(v[4], tendons[k].speed) << "sample " << k;
    EXPECT_EQ(v[5], tendons[k].tension) << "sample " << k;
    if (k > 0) largest_step_m = std::max(largest_step_m, std::abs(v[3] - tendons[k - 1].length));
  }
  EXPECT_GT(largest_step_m, 1e-5) << "the cord moves enough per step to tell a stale length";
  const auto tensions = b.Values("pend.cord.tendon.tension");
  EXPECT_GT(*std::max_element(tensions.begin(), tensions.end()), 1.0) << "taut for a while";
}

TEST_F(Fixture, AReloadedSceneIsNeverReadThroughItsOldSampler) {
  Recorder recorder(registry);
  SubscriptionOptions options;
  options.ids = {"pend.bob.position", "pend.bob.rotation", "pend.pivot.position"};
  options.batch_steps = 1;
  const SubscriptionId id = recorder.Subscribe(options);
  Step(1);
  recorder.OnStep(scene->steps(), scene->time());
  const std::weak_ptr<SceneSampler> old_sampler = channels.sampler;
  // as the Model reloads: channels out, then the old scene and its sampler freed
  registry.Clear();
  channels = SceneChannels();
  scene.reset();
  EXPECT_TRUE(old_sampler.expired()) << "nothing keeps the old sampler (and its scene) alive";
  recorder.OnStep(2, 0.002);
  const auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 2u);
  for (double v : batches[1].data) EXPECT_TRUE(std::isnan(v));
  EXPECT_EQ(recorder.Stats(id).stale.size(), 3u);
  Handle gone;
  EXPECT_FALSE(registry.TryResolve("pend.bob.position", &gone));
}

TEST_F(Fixture, WritesReachTheSceneAndRefusalsCarryItsReason) {
  registry.Set("pend.bob.mass", {2.5});
  EXPECT_NEAR(scene->GetParameter("bob.mass"), 2.5, 1e-6);  // Bullet keeps 1 / mass
  registry.Set("pend.motor.command", {3.0});
  EXPECT_EQ(scene->GetParameter("motor.command"), 3.0);
  ExpectThrowsWith<InvalidValue>([&] { registry.Set("pend.bob.mass", {-1.0}); },
                                 "mass must be positive");
  ExpectThrowsWith<InvalidValue>([&] { registry.Set("pend.pivot.position", {0.1}); },
                                 "pend.pivot.position: read-only");
  ExpectThrowsWith<InvalidValue>(
      [&] {
        registry.Set("pend.bob.position", {0, 0, 0});
      },
      "pend.bob.position: read-only");
  ExpectThrowsWith<InvalidValue>([&] { registry.Set("pend.bob.mass", {std::nan("")}); },
                                 "pend.bob.mass: value is NaN");
  ExpectThrowsWith<UnknownId>([&] { registry.Set("pend.bob.volume", {1.0}); },
                              "unknown id 'pend.bob.volume'");
  EXPECT_NEAR(scene->GetParameter("bob.mass"), 2.5, 1e-6);  // Bullet keeps 1 / mass
}

TEST_F(Fixture, SkipsIdsThatAnotherQuantityAlreadyHas) {
  // a hinge named like the body: its angle takes `bob.position` first
  auto other = physics_bullet::MakeScene(Pendulum("bob"));
  Registry r;
  const SceneChannels c = RegisterScene(r, "pend", *other);
  EXPECT_EQ(c.skipped, std::vector<std::string>{"pend.bob.position"});
  EXPECT_EQ(r.Info("pend.bob.position").unit, "rad");
  EXPECT_TRUE(r.Contains("pend.bob.orientation"));
}

TEST_F(Fixture, TheRecorderFollowsThePendulumThroughAReload) {
  Recorder recorder(registry);
  SubscriptionOptions options;
  options.ids = {"pend.bob.position", "pend.pivot.position"};
  options.every_n_steps = 10;
  options.batch_steps = 5;
  const SubscriptionId id = recorder.Subscribe(options);
  std::vector<double> angles;
  for (int i = 0; i < 100; ++i) {
    Step(1);
    if (scene->steps() % 10 == 1) angles.push_back(scene->GetParameter("pivot.position"));
    recorder.OnStep(scene->steps(), scene->time());
  }
  auto batches = recorder.TakeBatches(id);
  ASSERT_EQ(batches.size(), 2u);
  std::vector<double> recorded = batches[0].Values("pend.pivot.position");
  const auto second = batches[1].Values("pend.pivot.position");
  recorded.insert(recorded.end(), second.begin(), second.end());
  EXPECT_EQ(recorded, angles);
  EXPECT_EQ(batches[1].first_step, 51u);
  EXPECT_EQ((*batches[0].columns)[0].shape, Shape::Vector(3));

  // reload: the old channels go before the old scene, the new scene registers the same ids
  registry.RemoveMatching("pend.*");
  recorder.OnStep(scene->steps() + 1, scene->time());
  EXPECT_EQ(recorder.Stats(id).stale.size(), 2u);
  scene = physics_bullet::MakeScene(Pendulum());
  channels = RegisterScene(registry, "pend", *scene);
  for (int i = 0; i < 41; ++i) {  // samples at steps 1, 11, ..., 41
    Step(1);
    recorder.OnStep(scene->steps(), scene->time());
  }
  recorder.Flush();
  batches = recorder.TakeBatches(id);
  ASSERT_GE(batches.size(), 2u);
  EXPECT_EQ(batches[0].StaleIds().size(), 2u);
  EXPECT_TRUE(std::isnan(batches[0].data[0]));
  EXPECT_TRUE(batches.back().StaleIds().empty());
  EXPECT_EQ(batches.back().Values("pend.pivot.position").back(),
            scene->GetParameter("pivot.position"));
  for (size_t i = 1; i < batches.size(); ++i)
    EXPECT_EQ(batches[i].sequence, batches[i - 1].sequence + 1);
}

}  // namespace
}  // namespace caliper::daq
