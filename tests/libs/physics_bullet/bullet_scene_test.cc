// The Bullet adapter against analytic solutions: pendulum period, energy in a spring system,
// scale invariance, determinism, tendon forces, and faults that stop the step cleanly.
#include "caliper/physics_bullet/bullet_scene.h"

#include <gtest/gtest.h>

#include <cmath>

#include "test_kinds.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Vector3d;

constexpr double kG = 9.81;

sgal::Body Ball(const std::string& name, const Vector3d& position, double mass, double radius) {
  sgal::Body b;
  b.name = name;
  b.pose.position = position;
  b.inertia.mass = mass;
  b.inertia.tensor = Eigen::Matrix3d::Identity() * (0.4 * mass * radius * radius);
  b.shapes.push_back({"ball", sgal::Sphere{radius}, {}});
  return b;
}

/// A ball of mass m on a massless rod of length l, hinged to the world about y at the origin.
sgal::Scene Pendulum(double length, double angle, double dt = 1e-3) {
  sgal::Scene s;
  s.name = "pendulum";
  s.settings.time_step = dt;
  s.bodies.push_back(Ball("bob", Vector3d(length * std::sin(angle), 0, -length * std::cos(angle)),
                          1.0, 0.02));
  sgal::Constraint hinge;
  hinge.name = "pivot";
  hinge.kind = sgal::ConstraintKind::kHinge;
  hinge.body_a = "bob";
  // the pivot seen from the bob, with z along the world y axis
  const Eigen::Quaterniond z_to_y(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()));
  hinge.frame_a.position = -s.bodies[0].pose.position;
  hinge.frame_a.orientation = z_to_y;
  hinge.frame_b.orientation = z_to_y;
  s.constraints.push_back(hinge);
  return s;
}

/// Times between successive upward zero crossings of x (the bob's horizontal position).
double MeasuredPeriod(sgal::PhysicsScene& scene, double duration) {
  std::vector<double> crossings;
  double previous = scene.BodyStates()[0].pose.position.x();
  while (scene.time() < duration) {
    scene.Step();
    const double x = scene.BodyStates()[0].pose.position.x();
    if (previous < 0 && x >= 0)
      crossings.push_back(scene.time() - scene.description().settings.time_step * x / (x - previous));
    previous = x;
  }
  if (crossings.size() < 2) return 0;
  return (crossings.back() - crossings.front()) / (crossings.size() - 1);
}

TEST(BulletScene, PendulumPeriodMatchesTheAnalyticValue) {
  const double l = 0.5, r = 0.02, m = 1.0, angle = 0.05;
  auto scene = MakeScene(Pendulum(l, angle));
  // compound pendulum: I about the pivot = m l^2 + 2/5 m r^2; small-angle period, corrected to
  // second order in the amplitude (T0 (1 + angle^2 / 16))
  const double inertia = m * l * l + 0.4 * m * r * r;
  const double period = 2 * M_PI * std::sqrt(inertia / (m * kG * l)) * (1 + angle * angle / 16);
  const double measured = MeasuredPeriod(*scene, 10.0);
  EXPECT_NEAR(measured, period, 2e-3 * period) << "analytic " << period << " s";
  // the hinge angle reported equals the geometric angle
  EXPECT_LT(std::abs(scene->GetParameter("pivot.position")), angle * 1.01);
}

TEST(BulletScene, PendulumIsTheSameInMillimetres) {
  // the same model simulated with the engine in millimetres (world scale 1000) moves the same
  sgal::Scene metres = Pendulum(0.3, 0.3);
  sgal::Scene millimetres = metres;
  millimetres.settings.world_scale = 1000;
  auto a = MakeScene(metres);
  auto b = MakeScene(millimetres);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    a->Step();
    b->Step();
    worst = std::max(worst, (a->BodyStates()[0].pose.position - b->BodyStates()[0].pose.position).norm());
  }
  EXPECT_LT(worst, 1e-4) << "largest difference over 2 s [m]";
  EXPECT_GT(std::abs(a->BodyStates()[0].pose.position.x()), 0.01) << "it did move";
}

TEST(BulletScene, SameInputGivesBitIdenticalOutput) {
  auto run = [] {
    auto scene = MakeScene(Pendulum(0.4, 1.0));
    for (int i = 0; i < 3000; ++i) scene->Step();
    return scene->BodyStates()[0];
  };
  const auto a = run(), b = run();
  EXPECT_EQ(a.pose.position.x(), b.pose.position.x());
  EXPECT_EQ(a.pose.position.z(), b.pose.position.z());
  EXPECT_EQ(a.linear_velocity.x(), b.linear_velocity.x());
}

TEST(BulletScene, JointSpringConservesEnergyWithoutDamping) {
  // a bar turning about a vertical hinge against a torsion spring, no gravity
  sgal::Scene s;
  s.gravity = Vector3d::Zero();
  sgal::Body bar;
  bar.name = "bar";
  bar.inertia.mass = 2.0;
  bar.inertia.tensor = Vector3d(0.01, 0.05, 0.05).asDiagonal();
  bar.shapes.push_back({"box", sgal::Box{Vector3d(0.3, 0.05, 0.05)}, {}});
  bar.angular_velocity = Vector3d(0, 0, 2.0);
  s.bodies.push_back(bar);
  sgal::Constraint hinge;
  hinge.name = "spring_hinge";
  hinge.body_a = "bar";
  hinge.springs[0].stiffness = 3.0;
  s.constraints.push_back(hinge);
  auto scene = MakeScene(s);
  const double izz = 0.05, k = 3.0;
  auto energy = [&] {
    const double w = scene->GetParameter("spring_hinge.velocity");
    const double q = scene->GetParameter("spring_hinge.position");
    return 0.5 * izz * w * w + 0.5 * k * q * q;
  };
  const double e0 = 0.5 * izz * 4.0;
  double lo = e0, hi = e0;
  std::vector<double> crossings;  // times the angle passes zero [s]
  double previous = 0;
  for (int i = 0; i < 5000; ++i) {
    scene->Step();
    lo = std::min(lo, energy());
    hi = std::max(hi, energy());
    const double q = scene->GetParameter("spring_hinge.position");
    if (i > 0 && (previous < 0) != (q < 0)) crossings.push_back(scene->time());
    previous = q;
  }
  EXPECT_LT((hi - lo) / e0, 0.02) << "energy drifted between " << lo << " and " << hi << " J";
  // and it oscillated with the spring's period 2 pi sqrt(I/k) (two zero crossings a period)
  ASSERT_GE(crossings.size(), 4u);
  const double period = 2 * (crossings.back() - crossings.front()) / (crossings.size() - 1);
  EXPECT_NEAR(period, 2 * M_PI * std::sqrt(izz / k), 0.01 * 2 * M_PI * std::sqrt(izz / k));
}

TEST(BulletScene, TendonTensionHoldsAHangingBallAgainstGravity) {
  testing::RegisterTestKinds();
  sgal::Scene s;
  s.bodies.push_back(Ball("ball", Vector3d(0, 0, -0.5), 2.0, 0.05));
  sgal::Tendon t;
  t.name = "rope";
  sgal::PathElement top;
  top.position = Vector3d(0, 0, 0);  // fixed in the world
  sgal::PathElement bottom;
  bottom.body = "ball";
  bottom.position = Vector3d(0, 0, 0.05);
  t.path = {top, bottom};
  s.tendons.push_back(t);
  sgal::Actuator a;
  a.name = "holder";
  a.kind = "test_constant_tension";
  a.tendon = "rope";
  a.parameters["tension"] = 2.0 * kG;
  s.actuators.push_back(a);
  auto scene = MakeScene(s);
  for (int i = 0; i < 1000; ++i) scene->Step();
  EXPECT_NEAR(scene->BodyStates()[0].pose.position.z(), -0.5, 1e-6) << "equilibrium";
  EXPECT_NEAR(scene->GetParameter("rope.tendon.length"), 0.45, 1e-9);
  EXPECT_NEAR(scene->GetParameter("rope.tendon.tension"), 2.0 * kG, 1e-12);
  EXPECT_NEAR(scene->GetParameter("holder.seen_length"), 0.45, 1e-9);
  // twice the tension: the ball accelerates upward at g
  scene->SetCommand("holder", 4.0 * kG);
  for (int i = 0; i < 100; ++i) scene->Step();
  EXPECT_NEAR(scene->BodyStates()[0].linear_velocity.z(), kG * 0.1, 0.01 * kG * 0.1);
}

TEST(BulletScene, NonFiniteTensionStopsTheStepNamingTheActuator) {
  testing::RegisterTestKinds();
  sgal::Scene s;
  s.bodies.push_back(Ball("ball", Vector3d(0, 0, -0.5), 1.0, 0.05));
  sgal::Tendon t;
  t.name = "rope";
  sgal::PathElement top, bottom;
  bottom.body = "ball";
  t.path = {top, bottom};
  s.tendons.push_back(t);
  s.actuators.push_back({"faulty", "test_constant_tension", "rope", {{"nan_after", 10}}, {}});
  auto scene = MakeScene(s);
  for (int i = 0; i < 10; ++i) scene->Step();
  const auto before = scene->BodyStates()[0];
  try {
    scene->Step();
    FAIL() << "a NaN tension must stop the step";
  } catch (const sgal::SimulationFault& fault) {
    EXPECT_EQ(fault.element(), "faulty");
    EXPECT_NEAR(fault.time(), 0.011, 1e-9);
    EXPECT_NE(std::string(fault.what()).find("actuator 'faulty': tension is not finite"),
              std::string::npos);
  }
  EXPECT_EQ(scene->steps(), 10u);
  EXPECT_EQ(scene->BodyStates()[0].pose.position, before.pose.position) << "state kept";
}

TEST(BulletScene, ExplodingBodyStopsTheStepNamingTheBody) {
  sgal::Scene s;
  sgal::Body b = Ball("rocket", Vector3d::Zero(), 1.0, 0.1);
  b.linear_velocity = Vector3d(5e3, 0, 0);
  s.bodies.push_back(b);
  auto scene = MakeScene(s);
  try {
    scene->Step();
    FAIL() << "an exploding body must stop the step";
  } catch (const sgal::SimulationFault& fault) {
    EXPECT_EQ(fault.element(), "rocket");
    EXPECT_NE(std::string(fault.what()).find("speed"), std::string::npos) << fault.what();
  }
  EXPECT_EQ(scene->time(), 0.0);
}

TEST(BulletScene, RejectsAnInvalidSceneWithEveryProblem) {
  sgal::Scene s;
  s.source = "broken.dae";
  s.bodies.push_back(Ball("a", Vector3d::Zero(), -1, 0.1));
  s.constraints.push_back({});
  s.constraints[0].name = "j";
  s.constraints[0].body_a = "nobody";
  try {
    MakeScene(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("broken.dae: 3 problem(s)"), std::string::npos) << m;
    EXPECT_NE(m.find("body 'a': mass"), std::string::npos) << m;
    EXPECT_NE(m.find("constraint 'j': no body 'nobody'"), std::string::npos) << m;
  }
}

TEST(BulletScene, UnknownActuatorKindIsAClearError) {
  sgal::Scene s;
  s.bodies.push_back(Ball("a", Vector3d::Zero(), 1, 0.1));
  sgal::Tendon t;
  t.name = "t";
  sgal::PathElement p0, p1;
  p1.body = "a";
  t.path = {p0, p1};
  s.tendons.push_back(t);
  s.actuators.push_back({"pneumo", "pneumatic_muscle", "t", {}, {}});
  try {
    MakeScene(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("actuator 'pneumo': unknown kind 'pneumatic_muscle'"),
              std::string::npos)
        << e.what();
  }
}

TEST(BulletScene, ParametersAreListedReadAndWritten) {
  auto scene = MakeScene(Pendulum(0.5, 0.2));
  bool has_mass = false;
  for (const auto& p : scene->Parameters())
    if (p.id == "bob.mass") {
      has_mass = true;
      EXPECT_EQ(p.unit, "kg");
      EXPECT_TRUE(p.writable);
    }
  EXPECT_TRUE(has_mass);
  EXPECT_DOUBLE_EQ(scene->GetParameter("bob.mass"), 1.0);
  scene->SetParameter("bob.mass", 3.0);
  EXPECT_NEAR(scene->GetParameter("bob.mass"), 3.0, 1e-6);
  EXPECT_THROW(scene->SetParameter("bob.mass", -1), std::invalid_argument);
  EXPECT_THROW(scene->SetParameter("pivot.position", 1), std::invalid_argument);
  EXPECT_THROW(scene->GetParameter("nothing.here"), std::out_of_range);
  EXPECT_THROW(scene->SetParameter("bob.mass", NAN), std::invalid_argument);
}

}  // namespace
}  // namespace caliper::physics_bullet

namespace caliper::physics_bullet {
namespace {

struct Recorder : sgal::SceneObserver {
  std::vector<std::vector<int>> calls;
  void OnTransforms(uint64_t, double, const std::vector<int>& bodies,
                    const std::vector<sgal::BodyState>& states) override {
    EXPECT_EQ(bodies.size(), states.size());
    calls.push_back(bodies);
  }
};

TEST(ObserverHub, ReportsOnlyTheBodiesThatMoved) {
  sgal::Scene s = Pendulum(0.5, 0.3);
  sgal::Body wall;
  wall.name = "wall";
  wall.type = sgal::BodyType::kStatic;
  wall.pose.position = Vector3d(2, 0, 0);
  wall.shapes.push_back({"w", sgal::Box{}, {}});
  s.bodies.push_back(wall);
  auto scene = MakeScene(s);
  sgal::ObserverHub hub(1e-4, 1e-4);
  Recorder first, late;
  hub.Add(&first);
  scene->Step();
  hub.Notify(*scene);
  ASSERT_EQ(first.calls.size(), 1u);
  EXPECT_EQ(first.calls[0], (std::vector<int>{0, 1})) << "everything the first time";
  const int id = hub.Add(&late);
  for (int i = 0; i < 20; ++i) {
    scene->Step();
    hub.Notify(*scene);
  }
  for (size_t i = 1; i < first.calls.size(); ++i)
    EXPECT_EQ(first.calls[i], (std::vector<int>{0})) << "the static wall never moves";
  ASSERT_FALSE(late.calls.empty());
  EXPECT_EQ(late.calls[0], (std::vector<int>{0, 1}));
  hub.Remove(id);
  const size_t before = late.calls.size();
  scene->Step();
  hub.Notify(*scene);
  EXPECT_EQ(late.calls.size(), before);
}

}  // namespace
}  // namespace caliper::physics_bullet
