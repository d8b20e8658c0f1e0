// The Bullet adapter against analytic solutions: pendulum period, energy in a spring system,
// scale invariance, determinism, tendon forces, and faults that stop the step cleanly.
#include "caliper/physics_bullet/bullet_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

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
  s.bodies.push_back(
      Ball("bob", Vector3d(length * std::sin(angle), 0, -length * std::cos(angle)), 1.0, 0.02));
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
      crossings.push_back(scene.time() -
                          scene.description().settings.time_step * x / (x - previous));
    previous = x;
  }
  if (crossings.size() < 2) return 0;
  return (crossings.back() - crossings.front()) / (crossings.size() - 1);
}

// Two free bodies drifting and spinning without gravity: a ball whose centre of mass is its
// origin (its state read without the frame products) and a box whose centre of mass sits off its
// origin with a tensor off its axes. The states read into a reused buffer are those of
// BodyStates() bit for bit, and follow the motion: the centre of mass moves on a straight line,
// the box's origin turns about it.
TEST(BulletScene, ReadBodyStatesFillsAReusedBufferWithTheStatesOfBodyStates) {
  sgal::Scene s;
  s.name = "drift";
  s.gravity = Vector3d::Zero();
  sgal::Body ball;
  ball.name = "ball";
  ball.inertia.mass = 1;
  ball.inertia.tensor = Eigen::Matrix3d::Identity() * 0.004;
  ball.shapes.push_back({"s", sgal::Sphere{0.1}, {}});
  ball.linear_velocity = Vector3d(0.3, -0.2, 0.1);
  ball.angular_velocity = Vector3d(0, 0, 2);
  s.bodies.push_back(ball);
  sgal::Body box;
  box.name = "box";
  box.pose.position = Vector3d(1, 0, 0);
  box.inertia.mass = 2;
  box.inertia.com = Vector3d(0.05, 0.02, 0);
  box.inertia.tensor << 0.02, 0.001, 0, 0.001, 0.03, 0, 0, 0, 0.04;
  box.shapes.push_back({"b", sgal::Box{Vector3d(0.2, 0.1, 0.1)}, {}});
  box.linear_velocity = Vector3d(-0.1, 0, 0.2);
  box.angular_velocity = Vector3d(0, 0, 1);  // about z: the box's principal axis z
  s.bodies.push_back(box);
  auto scene = MakeScene(s);
  std::vector<sgal::BodyState> buffer(5);  // the wrong size, and reused below
  for (int step = 0; step < 500; ++step) scene->Step();
  for (int read = 0; read < 2; ++read) {
    scene->ReadBodyStates(&buffer);
    const std::vector<sgal::BodyState> fresh = scene->BodyStates();
    ASSERT_EQ(buffer.size(), 2u);
    for (size_t i = 0; i < fresh.size(); ++i) {
      EXPECT_EQ(buffer[i].pose.position, fresh[i].pose.position) << i;
      EXPECT_EQ(buffer[i].pose.orientation.coeffs(), fresh[i].pose.orientation.coeffs()) << i;
      EXPECT_EQ(buffer[i].linear_velocity, fresh[i].linear_velocity) << i;
      EXPECT_EQ(buffer[i].angular_velocity, fresh[i].angular_velocity) << i;
    }
  }
  const double t = scene->time();
  // the ball: its origin is its centre of mass, on a straight line, turned 2 t about z (to
  // Bullet's single precision)
  EXPECT_LT((buffer[0].pose.position - ball.linear_velocity * t).norm(), 1e-5);
  EXPECT_LT((buffer[0].linear_velocity - ball.linear_velocity).norm(), 1e-6);
  EXPECT_NEAR(buffer[0].pose.orientation.angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(2 * t, Vector3d::UnitZ()))),
              0, 1e-5);
  // the box: the centre of mass on its line, the origin turned t about it
  const Vector3d com0 = box.pose.position + box.inertia.com;
  const Vector3d com = com0 + box.linear_velocity * t;
  const Vector3d origin = com - Eigen::AngleAxisd(t, Vector3d::UnitZ()) * box.inertia.com;
  EXPECT_LT((buffer[1].pose.position - origin).norm(), 1e-5);
  const Vector3d origin_velocity =
      box.linear_velocity + Vector3d(0, 0, 1).cross(buffer[1].pose.position - com);
  EXPECT_LT((buffer[1].linear_velocity - origin_velocity).norm(), 1e-5);
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
    worst = std::max(worst,
                     (a->BodyStates()[0].pose.position - b->BodyStates()[0].pose.position).norm());
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
  // twice the tension: the ball accelerates upward at g. The first step still pulls with the
  // tension from the end of the last one (an actuator's new tension acts through the next step).
  scene->SetCommand("holder", 4.0 * kG);
  scene->Step();
  EXPECT_NEAR(scene->BodyStates()[0].linear_velocity.z(), 0, 1e-6);
  for (int i = 0; i < 100; ++i) scene->Step();
  EXPECT_NEAR(scene->BodyStates()[0].linear_velocity.z(), kG * 0.1, 0.001 * kG * 0.1);
}

/// A 1 kg ball hanging on a rope from the origin, pulled by the test kind test_constant_tension
/// named `actuator` with these parameters.
sgal::Scene BallOnRope(const std::string& actuator,
                       const std::map<std::string, double>& parameters) {
  testing::RegisterTestKinds();
  sgal::Scene s;
  s.bodies.push_back(Ball("ball", Vector3d(0, 0, -0.5), 1.0, 0.05));
  sgal::Tendon t;
  t.name = "rope";
  sgal::PathElement top, bottom;
  bottom.body = "ball";
  t.path = {top, bottom};
  s.tendons.push_back(t);
  s.actuators.push_back({actuator, "test_constant_tension", "rope", parameters, {}});
  return s;
}

TEST(BulletScene, NonFiniteTensionStopsTheStepNamingTheActuator) {
  auto scene = MakeScene(BallOnRope("faulty", {{"nan_after", 10}}));
  for (int i = 0; i < 10; ++i) scene->Step();
  const auto before = scene->BodyStates()[0];
  try {
    scene->Step();
    FAIL() << "a NaN tension must stop the step";
  } catch (const sgal::SimulationFault& fault) {
    EXPECT_EQ(fault.element(), "faulty");
    EXPECT_NEAR(fault.time(), 0.011, 1e-9);
    EXPECT_NE(std::string(fault.what())
                  .find("actuator 'faulty' (test_constant_tension): tension is not finite"),
              std::string::npos)
        << fault.what();
  }
  EXPECT_EQ(scene->steps(), 10u);
  EXPECT_EQ(scene->BodyStates()[0].pose.position, before.pose.position) << "state kept";
}

TEST(BulletScene, ATensionBeyondTheBoundStopsTheStepBeforeItActs) {
  // a tension computed at the end of a step acts through the next one: a wild one (a muscle
  // driven past its curves by a path that jumped) faults the step that made it, so that a rewind
  // or an undo does not carry it on
  Options options;
  options.max_tension = 1e5;
  auto scene = MakeScene(BallOnRope("wild", {{"tension", 1}}), options);
  for (int i = 0; i < 10; ++i) scene->Step();
  const auto before = scene->BodyStates()[0];
  scene->SetCommand("wild", 2e5);
  try {
    scene->Step();
    FAIL() << "a tension beyond the bound must stop the step";
  } catch (const sgal::SimulationFault& fault) {
    EXPECT_EQ(fault.element(), "wild");
    EXPECT_NE(std::string(fault.what())
                  .find("tension 200000.000000 N beyond the engine's bound "
                        "of 100000.000000 N"),
              std::string::npos)
        << fault.what();
  }
  EXPECT_EQ(scene->steps(), 10u);
  EXPECT_EQ(scene->BodyStates()[0].pose.position, before.pose.position) << "state kept";
  EXPECT_EQ(scene->GetParameter("rope.tendon.tension"), 1.0) << "the tension that acted last";
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

/// A tendon from a point fixed in the world to the centre of a body.
sgal::Tendon TendonTo(const std::string& name, const Vector3d& anchor, const std::string& body) {
  sgal::Tendon t;
  t.name = name;
  sgal::PathElement from;
  from.position = anchor;
  sgal::PathElement to;
  to.body = body;
  t.path = {from, to};
  return t;
}

/// The pendulum pulled by a DC motor with a Zener element, a muscle with an elastic tendon, a
/// ligament and the test kind that fails on purpose ("faulty", a DC motor too): on a tendon of
/// its own after all the others, or sharing the first motor's tendon after it.
/// A pendulum starting at `angle` held by a DC motor (zener tendon), an elastic-tendon muscle and a
/// ligament, each on its own tendon.
sgal::Scene ThreePullers(double angle) {
  sgal::Scene s = Pendulum(0.4, angle);
  const std::string bob = s.bodies[0].name;
  s.tendons.push_back(TendonTo("t_motor", Vector3d(0.35, 0, -0.3), bob));
  s.tendons.push_back(TendonTo("t_muscle", Vector3d(-0.35, 0, -0.3), bob));
  s.tendons.push_back(TendonTo("t_ligament", Vector3d(0, 0, -0.8), bob));
  s.actuators.push_back(
      {"motor", "dc_motor_tendon", "t_motor", {{"pretension", 2}}, {{"elastic", "zener"}}});
  s.actuators.push_back(
      {"muscle",
       "hill_muscle",
       "t_muscle",
       {{"optimal_fiber_length", 0.1}, {"tendon_slack_length", 0.25}, {"max_isometric_force", 30}},
       {{"tendon", "elastic"}}});
  s.actuators.push_back(
      {"ligament", "ligament", "t_ligament", {{"stiffness", 300}, {"rest_length", 0.39}}, {}});
  return s;
}

sgal::Scene PulledPendulum(bool share_tendon) {
  sgal::Scene s = ThreePullers(0.0);
  if (!share_tendon)
    s.tendons.push_back(TendonTo("t_faulty", Vector3d(0.35, 0, -0.5), s.bodies[0].name));
  s.actuators.push_back({"faulty",
                         "test_faulty_motor",
                         share_tendon ? "t_motor" : "t_faulty",
                         {{"pretension", 1}, {"stiffness", 2000}},
                         {}});
  return s;
}

std::unique_ptr<sgal::PhysicsScene> MakePulledPendulum(bool share_tendon) {
  auto scene = MakeScene(PulledPendulum(share_tendon));
  scene->SetCommand("motor", 0.05);  // [V]
  scene->SetCommand("muscle", 0.4);
  scene->SetCommand("faulty", -0.03);
  return scene;
}

/// Everything a scene reports, by name: time, step count, body states, tendon states and every
/// parameter and state (but the test kind's switch `fail`).
std::vector<std::pair<std::string, double>> Everything(const sgal::PhysicsScene& scene) {
  std::vector<std::pair<std::string, double>> all = {{"time", scene.time()},
                                                     {"steps", static_cast<double>(scene.steps())}};
  const auto bodies = scene.BodyStates();
  for (size_t i = 0; i < bodies.size(); ++i) {
    const std::string n = scene.description().bodies[i].name + ".";
    const sgal::BodyState& b = bodies[i];
    for (int k = 0; k < 3; ++k) {
      all.push_back({n + "position", b.pose.position[k]});
      all.push_back({n + "linear_velocity", b.linear_velocity[k]});
      all.push_back({n + "angular_velocity", b.angular_velocity[k]});
    }
    for (int k = 0; k < 4; ++k) all.push_back({n + "orientation", b.pose.orientation.coeffs()[k]});
  }
  const auto tendons = scene.TendonStates();
  for (size_t i = 0; i < tendons.size(); ++i) {
    const std::string n = scene.description().tendons[i].name + ".state.";
    all.push_back({n + "length", tendons[i].length});
    all.push_back({n + "speed", tendons[i].speed});
    all.push_back({n + "tension", tendons[i].tension});
    all.push_back({n + "contacts", static_cast<double>(tendons[i].contacts)});
    for (const auto& p : tendons[i].points)
      for (int k = 0; k < 3; ++k) all.push_back({n + "points", p[k]});
  }
  const auto parameters = scene.Parameters();
  for (size_t i = 0; i < parameters.size(); ++i)
    if (parameters[i].id != "faulty.fail")
      all.push_back({parameters[i].id, scene.GetParameter(static_cast<int>(i))});
  return all;
}

void ExpectSameBits(const std::vector<std::pair<std::string, double>>& expected,
                    const std::vector<std::pair<std::string, double>>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  int differences = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(expected[i].first, actual[i].first);
    if (std::memcmp(&expected[i].second, &actual[i].second, sizeof(double)) != 0 &&
        ++differences <= 10)
      ADD_FAILURE() << expected[i].first << ": " << expected[i].second
                    << " != " << actual[i].second;
  }
  EXPECT_EQ(differences, 0);
}

// the next step of `scene` fails in the actuator 'faulty' (test_faulty_motor) at `time` [s], its
// message holding `detail`
void ExpectFaultingStep(sgal::PhysicsScene* scene, const std::string& detail, double time) {
  try {
    scene->Step();
    ADD_FAILURE() << "the step must fail";
  } catch (const sgal::SimulationFault& fault) {
    const std::string what = fault.what();
    EXPECT_EQ(fault.element(), "faulty");
    EXPECT_NEAR(fault.time(), time, 1e-12);
    EXPECT_EQ(what.rfind("actuator 'faulty' (test_faulty_motor)", 0), 0u) << what;
    EXPECT_NE(what.find(detail), std::string::npos) << what;
  }
}

// the next step of `scene`, made to fail in 'faulty' at `time` [s], leaves the scene as it was,
// bit for bit
void ExpectAFaultingStepPutBack(sgal::PhysicsScene* scene, double time) {
  const auto before = Everything(*scene);
  scene->SetParameter("faulty.fail", 1);
  ExpectFaultingStep(scene, "injected fault", time);
  scene->SetParameter("faulty.fail", 0);
  ExpectSameBits(before, Everything(*scene));
}

// An actuator that cannot put its step back (TendonActuator's contract broken, here on purpose)
// is reported after everything else was put back: the bodies, the other actuators, the joints'
// and the paths' readings.
TEST(BulletScene, AnActuatorThatCannotPutItsStepBackIsReportedAfterTheRest) {
  testing::RegisterTestKinds();
  auto faulting = MakePulledPendulum(false);
  for (int i = 0; i < 25; ++i) faulting->Step();
  const auto before = Everything(*faulting);
  faulting->SetParameter("faulty.fail", 6);
  try {
    faulting->Step();
    ADD_FAILURE() << "the step went on";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "injected restore fault");
  }
  EXPECT_EQ(faulting->steps(), 25u);
  faulting->SetParameter("faulty.fail", 0);
  ExpectSameBits(before, Everything(*faulting));
}

TEST(BulletScene, AnyFaultInAStepEndsAtTheStartOfThatStep) {
  testing::RegisterTestKinds();
  const std::pair<int, std::string> faults[] = {
      {1,
       "failed at t = 0.026000 s: std::runtime_error: injected fault; simulation stopped at "
       "t = 0.025000 s (step 25)"},
      {2, "failed at t = 0.026000 s: std::bad_alloc;"},
      {3, ": tension is not finite (nan) at t = 0.026000 s"},
      {4, "failed at t = 0.026000 s: an exception of type int;"}};
  for (const bool share_tendon : {false, true}) {
    for (const auto& [mode, detail] : faults) {
      SCOPED_TRACE("fail = " + std::to_string(mode) + (share_tendon ? ", shared tendon" : ""));
      auto faulting = MakePulledPendulum(share_tendon);
      auto reference = MakePulledPendulum(share_tendon);
      for (int i = 0; i < 25; ++i) {
        faulting->Step();
        reference->Step();
      }
      const auto before = Everything(*faulting);
      faulting->SetParameter("faulty.fail", mode);
      for (int attempt = 0; attempt < 2; ++attempt) {  // and again: the same fault, same state
        ExpectFaultingStep(faulting.get(), detail, 0.026);
        EXPECT_EQ(faulting->steps(), 25u);
        ExpectSameBits(before, Everything(*faulting));
      }
      // disarmed, it steps on exactly as a scene that never faulted: every actuator was restored
      faulting->SetParameter("faulty.fail", 0);
      for (int i = 0; i < 25; ++i) {
        faulting->Step();
        reference->Step();
      }
      ExpectSameBits(Everything(*reference), Everything(*faulting));
      EXPECT_GT(std::abs(faulting->GetParameter("motor.current")), 1e-3) << "the motors ran";
      EXPECT_GT(faulting->GetParameter("muscle.tension"), 0);
      EXPECT_GT(faulting->GetParameter("ligament.tension"), 0);
    }
  }
}

TEST(BulletScene, AFaultingStepPutsTheDelayedChannelsBack) {
  testing::RegisterTestKinds();
  // a fault in an actuator's step, before the channels are read, and one in the reading itself
  // (faulty.current, after motor.current's ring took its value and before ligament.tension's)
  const std::pair<int, std::string> faults[] = {
      {1, "failed at t = 0.026000 s: std::runtime_error: injected fault;"},
      {5, "failed at t = 0.026000 s: std::runtime_error: injected reading fault;"}};
  sgal::Scene s = PulledPendulum(false);
  s.measurement_delays = {{"motor.current", 0.003},
                          {"faulty.current", 0.002},
                          {"ligament.tension", 0.004},
                          {"pivot.position", 0.0}};
  for (const auto& [mode, detail] : faults) {
    SCOPED_TRACE("fail = " + std::to_string(mode));
    auto faulting = MakeScene(s);
    auto reference = MakeScene(s);
    for (auto* scene : {faulting.get(), reference.get()}) {
      scene->SetCommand("motor", 0.05);  // [V]
      scene->SetCommand("muscle", 0.4);
      scene->SetCommand("faulty", -0.03);
      for (int i = 0; i < 25; ++i) scene->Step();
    }
    const auto before = Everything(*faulting);
    const std::vector<double> rings = faulting->SaveDynamicState().measurements;
    ASSERT_EQ(rings.size(), 4u + 3u + 5u + 1u);
    faulting->SetParameter("faulty.fail", mode);
    ExpectFaultingStep(faulting.get(), detail, 0.026);
    faulting->SetParameter("faulty.fail", 0);
    EXPECT_EQ(faulting->steps(), 25u);
    ExpectSameBits(before, Everything(*faulting));  // the delayed and true values among them
    const std::vector<double> after = faulting->SaveDynamicState().measurements;
    ASSERT_EQ(after.size(), rings.size());
    EXPECT_EQ(std::memcmp(after.data(), rings.data(), rings.size() * sizeof(double)), 0);
    // it steps on exactly as a scene that never faulted, the delayed channels too
    for (int i = 0; i < 25; ++i) {
      faulting->Step();
      reference->Step();
    }
    ExpectSameBits(Everything(*reference), Everything(*faulting));
    EXPECT_NE(faulting->GetParameter("motor.current"),
              faulting->GetParameter("motor.current.undelayed"));
  }
}

// A command delay lengthened live to 200 steps (four times the line's old bound): the motor's
// state grows with its line, and a faulting step (after the motor has taken its command) puts
// all 200 commands in flight back. Shortened live, the line keeps what will still be followed;
// the state saved under the long delay restores into a scene built with the short one (as a
// scene edit carries it over) and goes on bit for bit as the scene shortened live.
TEST(BulletScene, ALongCommandDelayEditedLiveKeepsItsCommandsInFlight) {
  testing::RegisterTestKinds();
  const auto command = [](int step) { return 0.05 * std::sin(0.03 * step); };  // [V]
  auto faulting = MakePulledPendulum(false);
  auto reference = MakePulledPendulum(false);
  const auto motor = [](const sgal::Scene& scene) {
    size_t k = 0;
    while (scene.actuators.at(k).name != "motor") ++k;
    return k;
  };
  const auto motor_state_size = [&](const sgal::PhysicsScene& scene) {
    return scene.SaveDynamicState().actuators.at(motor(scene.description())).size();
  };
  const size_t undelayed = motor_state_size(*faulting);
  for (auto* scene : {faulting.get(), reference.get()})
    scene->SetParameter("motor.command_delay", 0.2);
  EXPECT_EQ(motor_state_size(*faulting), undelayed + 2 * 200);
  auto step_both = [&](int step) {
    for (auto* scene : {faulting.get(), reference.get()}) {
      scene->SetCommand("motor", command(step));
      scene->Step();
    }
  };
  for (int i = 0; i < 250; ++i) step_both(i);
  EXPECT_EQ(faulting->GetParameter("motor.delayed_command"), command(249 - 200));
  faulting->SetCommand("motor", command(250));
  ExpectAFaultingStepPutBack(faulting.get(), 0.251);
  for (int i = 250; i < 300; ++i) step_both(i);
  ExpectSameBits(Everything(*reference), Everything(*faulting));
  EXPECT_EQ(faulting->GetParameter("motor.delayed_command"), command(299 - 200));

  // saved with 200 commands in flight, then shortened live to 20 steps
  const sgal::DynamicState saved = faulting->SaveDynamicState();
  faulting->SetParameter("motor.command_delay", 0.02);
  EXPECT_EQ(motor_state_size(*faulting), undelayed + 2 * 20);
  sgal::Scene edited = PulledPendulum(false);
  edited.actuators[motor(edited)].parameters["command_delay"] = 0.02;
  auto restored = MakeScene(edited);
  restored->RestoreDynamicState(saved);
  EXPECT_EQ(motor_state_size(*restored), undelayed + 2 * 20);
  faulting->ResetCaches();  // as a keyframe does: the hinge's warm start from the same place
  restored->ResetCaches();
  for (int i = 300; i < 400; ++i) {
    for (auto* scene : {faulting.get(), restored.get()}) {
      scene->SetCommand("motor", command(i));
      scene->Step();
    }
    // at once the command of 20 steps before, no longer that of 200
    ASSERT_EQ(faulting->GetParameter("motor.delayed_command"), command(i - 20)) << i;
  }
  ExpectSameBits(Everything(*faulting), Everything(*restored));
  EXPECT_GT(std::abs(faulting->GetParameter("motor.current")), 1e-3) << "the motor ran";

  // a state that is no delay line's is refused, naming the actuator
  sgal::DynamicState wrong = saved;
  wrong.actuators[motor(edited)].pop_back();
  try {
    restored->RestoreDynamicState(wrong);
    ADD_FAILURE() << "a cut state was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("actuator 'motor' cannot read"), std::string::npos)
        << e.what();
  }
}

// The same for a muscle's excitations: a faulting step (after the muscle has taken its
// excitation) puts its 200 in flight back, and it goes on bit for bit as one that never faulted.
TEST(BulletScene, AFaultingStepPutsBackAMusclesExcitationsInFlight) {
  testing::RegisterTestKinds();
  const auto excitation = [](int step) { return 0.3 + 0.2 * std::sin(0.05 * step); };  // [-]
  auto faulting = MakePulledPendulum(false);
  auto reference = MakePulledPendulum(false);
  for (auto* scene : {faulting.get(), reference.get()})
    scene->SetParameter("muscle.command_delay", 0.2);
  auto step_both = [&](int step) {
    for (auto* scene : {faulting.get(), reference.get()}) {
      scene->SetCommand("muscle", excitation(step));
      scene->Step();
    }
  };
  for (int i = 0; i < 250; ++i) step_both(i);
  faulting->SetCommand("muscle", excitation(250));
  ExpectAFaultingStepPutBack(faulting.get(), 0.251);
  for (int i = 250; i < 300; ++i) {
    step_both(i);
    ASSERT_EQ(faulting->GetParameter("muscle.delayed_command"), excitation(i - 200)) << i;
  }
  ExpectSameBits(Everything(*reference), Everything(*faulting));
  EXPECT_GT(faulting->GetParameter("muscle.tension"), 0);
}

TEST(BulletScene, AnExplodingBodyPutsTheActuatorsBackToo) {
  sgal::Scene s;
  s.gravity = Vector3d(5000, 0, 0);  // 5 m/s more each step: over the 1000 m/s limit at step 5
  sgal::Body b = Ball("rocket", Vector3d::Zero(), 1.0, 0.1);
  b.linear_velocity = Vector3d(980, 0, 0);
  s.bodies.push_back(b);
  // a soft line the rocket pays out, its motor running meanwhile
  s.tendons.push_back(TendonTo("line", Vector3d(-1, 0, 0), "rocket"));
  s.actuators.push_back(
      {"winch", "dc_motor_tendon", "line", {{"pretension", 1}, {"stiffness", 10}}, {}});
  auto scene = MakeScene(s);
  scene->SetCommand("winch", 1);
  std::vector<std::pair<std::string, double>> before;
  try {
    for (int i = 0; i < 1000; ++i) {
      before = Everything(*scene);
      scene->Step();
    }
    FAIL() << "the rocket must exceed the speed limit";
  } catch (const sgal::SimulationFault& fault) {
    EXPECT_EQ(fault.element(), "rocket");
    EXPECT_NE(std::string(fault.what()).find("speed"), std::string::npos) << fault.what();
  }
  EXPECT_GT(scene->steps(), 2u);
  EXPECT_NE(scene->GetParameter("winch.current"), 0);
  ExpectSameBits(before, Everything(*scene));
}

TEST(BulletScene, RefusesAMaxSubstepOrTimeStepThatWouldMakeAStepTooLong) {
  sgal::Scene s = Pendulum(0.4, 0.0);
  s.tendons.push_back(TendonTo("t1", Vector3d(0.35, 0, -0.3), "bob"));
  s.tendons.push_back(TendonTo("t2", Vector3d(-0.35, 0, -0.3), "bob"));
  s.actuators.push_back({"m1", "dc_motor_tendon", "t1", {}, {}});
  s.actuators.push_back({"m2", "dc_motor_tendon", "t2", {}, {}});
  auto scene = MakeScene(s);
  try {
    scene->SetParameter("m2.max_substep", 1e-12);
    FAIL() << "10^9 sub-steps per step accepted";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("actuator 'm2' (dc_motor_tendon): parameter 'max_substep' = 1e-12"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("max_substep must be at least 1e-07 s"), std::string::npos) << m;
  }
  EXPECT_EQ(scene->GetParameter("m2.max_substep"), 1e-3);
  EXPECT_EQ(scene->description().actuators[1].parameters.count("max_substep"), 0u);
  scene->SetParameter("m2.max_substep", 1e-6);

  // m1 takes a 50 ms step, m2 cannot (5*10^4 sub-steps): refused, and m1 keeps 1 ms too
  try {
    scene->SetParameter("simulation.time_step", 0.05);
    FAIL() << "5*10^4 sub-steps per step accepted";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("simulation.time_step = 0.05 s refused: actuator 'm2'"), std::string::npos)
        << m;
    EXPECT_NE(m.find("or the time step at most 0.01 s"), std::string::npos) << m;
  }
  EXPECT_EQ(scene->GetParameter("simulation.time_step"), 1e-3);
  scene->SetParameter("m1.max_substep", 1e-7);  // allowed at 1 ms, not at 50 ms
  scene->Step();
  EXPECT_NEAR(scene->time(), 1e-3, 1e-15);
  // the longest step both can take
  scene->SetParameter("m1.max_substep", 1e-6);
  scene->SetParameter("simulation.time_step", 0.01);
  EXPECT_THROW(scene->SetParameter("m1.max_substep", 1e-7), std::invalid_argument);
  scene->Step();
  EXPECT_NEAR(scene->time(), 0.011, 1e-12);
}

TEST(BulletScene, RefusesASceneWhoseStepsCannotBeBounded) {
  sgal::Scene s = Pendulum(0.4, 0.0);
  s.settings.solver_iterations = 1000000;
  try {
    MakeScene(s);
    FAIL() << "10^6 solver iterations per step accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("solver_iterations = 1000000 is out of range"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("[1, 10000]"), std::string::npos) << e.what();
  }
  s.settings.solver_iterations = 0;
  EXPECT_THROW(MakeScene(s), std::invalid_argument);
  s.settings.solver_iterations = 10000;
  EXPECT_NO_THROW(MakeScene(s));

  // a scene's own time step that an actuator cannot take in 10^4 sub-steps
  s.settings.solver_iterations = 10;
  s.settings.time_step = 30;
  s.tendons.push_back(TendonTo("t1", Vector3d(0.35, 0, -0.3), "bob"));
  s.actuators.push_back({"m1", "dc_motor_tendon", "t1", {}, {}});
  try {
    MakeScene(s);
    FAIL() << "a 30 s step of 3e4 motor sub-steps accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("actuator 'm1' (dc_motor_tendon): a time step of 30 s"),
              std::string::npos)
        << e.what();
  }
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

// A convex hull given with many points inside and on its faces (as CAD meshes are) rests on a
// floor exactly as the hull of its corners does: the adapter keeps the corners only.
namespace caliper::physics_bullet {
namespace {

double RestingHeight(std::shared_ptr<sgal::Mesh> mesh) {
  sgal::Scene scene;
  sgal::Body floor;
  floor.name = "floor";
  floor.type = sgal::BodyType::kStatic;
  sgal::Shape plane;
  plane.name = "floor";
  plane.geometry = sgal::Plane{};
  floor.shapes.push_back(plane);
  scene.bodies.push_back(floor);
  sgal::Body block;
  block.name = "block";
  block.pose.position = Eigen::Vector3d(0, 0, 0.2);
  block.inertia.mass = 1;
  block.inertia.tensor = Eigen::Matrix3d::Identity() * (1.0 / 6.0) * 0.01;  // 0.1 m cube
  sgal::Shape hull;
  hull.name = "hull";
  hull.geometry = sgal::ConvexHull{mesh};
  block.shapes.push_back(hull);
  scene.bodies.push_back(block);
  auto physics = MakeScene(scene);
  for (int i = 0; i < 1000; ++i) physics->Step();
  return physics->BodyStates()[1].pose.position.z();
}

TEST(BulletScene, AHullOfManyPointsCollidesAsTheHullOfItsCorners) {
  auto corners = std::make_shared<sgal::Mesh>();
  for (float x : {-0.05f, 0.05f})
    for (float y : {-0.05f, 0.05f})
      for (float z : {-0.05f, 0.05f}) corners->vertices.emplace_back(x, y, z);
  auto dense = std::make_shared<sgal::Mesh>(*corners);
  // 2000 points inside and on the faces of the same cube
  uint32_t state = 12345;
  auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return static_cast<float>(state >> 8) / static_cast<float>(1u << 24) * 0.1f - 0.05f;
  };
  for (int i = 0; i < 2000; ++i) {
    Eigen::Vector3f p(next(), next(), next());
    if (i % 2 == 0) p[i % 3] = i % 4 == 0 ? 0.05f : -0.05f;  // on a face
    dense->vertices.push_back(p);
  }
  const double expected = RestingHeight(corners);
  EXPECT_NEAR(expected, 0.05, 5e-4);  // half the edge: no margin outside the hull
  EXPECT_NEAR(RestingHeight(dense), expected, 1e-6);
}

}  // namespace
}  // namespace caliper::physics_bullet

// A hinge's position counts whole turns: a wheel spinning at 10 rad/s for 1 s reads 10 rad, not
// 10 - 4 pi, so continuous joints, multi-turn limits and coupled leaders read on past +-pi.
namespace caliper::physics_bullet {
namespace {

// A wheel on a hinge "axle" about z, spinning at 10 rad/s, no gravity; limits lower .. upper
// [rad] (free when lower > upper).
sgal::Scene SpinningWheel(double lower = 1, double upper = -1) {
  sgal::Scene scene;
  scene.gravity.setZero();
  sgal::Body base;
  base.name = "base";
  base.type = sgal::BodyType::kStatic;
  scene.bodies.push_back(base);
  sgal::Body wheel;
  wheel.name = "wheel";
  wheel.inertia.mass = 1;
  wheel.inertia.tensor = Eigen::Matrix3d::Identity() * 0.01;
  wheel.angular_velocity = Eigen::Vector3d(0, 0, 10);  // [rad/s]
  scene.bodies.push_back(wheel);
  sgal::Constraint axle;
  axle.name = "axle";
  axle.body_a = "wheel";
  axle.body_b = "base";
  axle.limits[0].lower = lower;
  axle.limits[0].upper = upper;
  scene.constraints.push_back(axle);
  return scene;
}

TEST(BulletScene, HingePositionCountsWholeTurns) {
  auto physics = MakeScene(SpinningWheel());
  double last = physics->GetParameter("axle.position");
  for (int i = 0; i < 1000; ++i) {
    physics->Step();
    const double now = physics->GetParameter("axle.position");
    ASSERT_GT(now, last) << "step " << i;  // never jumps back by a turn
    last = now;
  }
  EXPECT_NEAR(last, 10.0, 1e-3);
}

// A step that fails while a hinge passes +-pi is put back with the turn it counted: the wheel is
// where it was, bit for bit, and the step taken again reads past pi, not a turn below it.
TEST(BulletScene, AFaultingStepPutsBackTheTurnItCounted) {
  testing::RegisterTestKinds();
  sgal::Scene description = SpinningWheel();
  // the test kind that fails on purpose, on a tendon along the axle (no torque on the wheel)
  description.tendons.push_back(TendonTo("t_faulty", Vector3d(0, 0, 1), "wheel"));
  description.actuators.push_back(
      {"faulty", "test_faulty_motor", "t_faulty", {{"pretension", 1}, {"stiffness", 2000}}, {}});
  auto physics = MakeScene(description);
  for (int i = 0; i < 314; ++i) physics->Step();  // 10 rad/s: 3.14 rad, pi in the next step
  const double before = physics->GetParameter("axle.position");
  ASSERT_LT(before, M_PI);
  ASSERT_GT(before, M_PI - 0.01);
  ExpectAFaultingStepPutBack(physics.get(), 0.315);
  EXPECT_EQ(physics->GetParameter("axle.position"), before);
  physics->Step();
  EXPECT_GT(physics->GetParameter("axle.position"), M_PI);
  EXPECT_NEAR(physics->GetParameter("axle.position"), before + 0.01, 1e-4);
}

// The step counts a hinge's turns without computing its angle, which is read on demand: a wheel
// nobody reads while it spins either way still reads its whole turns, and a state saved at 10 rad
// goes on from 10 rad in a scene built afresh.
TEST(BulletScene, HingeCountsTurnsThatNobodyRead) {
  for (const double spin : {10.0, -10.0}) {
    sgal::Scene description = SpinningWheel();
    description.bodies[1].angular_velocity = Eigen::Vector3d(0, 0, spin);
    auto physics = MakeScene(description);
    for (int i = 0; i < 1000; ++i) physics->Step();
    const double at_1s = physics->GetParameter("axle.position");
    EXPECT_NEAR(at_1s, spin, 1e-3) << "spin " << spin;

    const sgal::DynamicState saved = physics->SaveDynamicState();
    ASSERT_EQ(saved.joint_positions.size(), 1u);
    EXPECT_EQ(saved.joint_positions[0], at_1s);
    auto fresh = MakeScene(description);
    fresh->RestoreDynamicState(saved);
    EXPECT_EQ(fresh->GetParameter("axle.position"), at_1s) << "spin " << spin;
    EXPECT_EQ(fresh->SaveDynamicState().engine, saved.engine) << "spin " << spin;
    // by the body poses alone (as a scene edit carries a run over): the turns from the angle
    sgal::DynamicState by_poses = saved;
    by_poses.engine.clear();
    auto edited = MakeScene(description);
    edited->RestoreDynamicState(by_poses);
    EXPECT_NEAR(edited->GetParameter("axle.position"), at_1s, 1e-6) << "spin " << spin;
    for (int i = 0; i < 500; ++i) {
      physics->Step();
      fresh->Step();
      edited->Step();
    }
    EXPECT_NEAR(physics->GetParameter("axle.position"), 1.5 * spin, 1e-3) << "spin " << spin;
    EXPECT_NEAR(fresh->GetParameter("axle.position"), 1.5 * spin, 1e-3) << "spin " << spin;
    EXPECT_NEAR(edited->GetParameter("axle.position"), 1.5 * spin, 1e-3) << "spin " << spin;
  }
}

}  // namespace
}  // namespace caliper::physics_bullet

// Limits of a hinge beyond +-pi, as URDF arms have them: a span of a full turn or more has no
// stops (Bullet keeps its stops within one turn); a span of less than a turn that lies beyond pi
// holds the joint inside it, on the side of the circle where it lies.
namespace caliper::physics_bullet {
namespace {

// A wheel on a hinge about z spun at 10 rad/s without gravity for 1 s: the lowest and highest
// positions it reached [rad] (a stop throws it back: Bullet's limits bounce).
std::pair<double, double> SpunWheel(double lower, double upper) {
  auto physics = MakeScene(SpinningWheel(lower, upper));
  std::pair<double, double> range(0, 0);
  for (int i = 0; i < 1000; ++i) {
    physics->Step();
    const double q = physics->GetParameter("axle.position");
    range = {std::min(range.first, q), std::max(range.second, q)};
  }
  return range;
}

TEST(BulletScene, HingeLimitsBeyondHalfATurn) {
  // -2 pi .. 2 pi (a UR5's): free, the wheel turns on to 10 rad
  EXPECT_NEAR(SpunWheel(-2 * M_PI, 2 * M_PI).second, 10.0, 1e-2);
  // -0.5 .. 2.5 rad: held between the stops
  auto [low, high] = SpunWheel(-0.5, 2.5);
  EXPECT_NEAR(high, 2.5, 0.05);
  EXPECT_GT(low, -0.55);
  // -4.0 .. 2.0: a span of less than a turn reaching past -pi; spinning up, the wheel stops at
  // 2.0 (thrown back, it reaches -0.39 rad in the second left)
  std::tie(low, high) = SpunWheel(-4.0, 2.0);
  EXPECT_NEAR(high, 2.0, 0.05);
  EXPECT_GT(low, -4.05);
}

}  // namespace
}  // namespace caliper::physics_bullet

namespace caliper::physics_bullet {
namespace {

// A pendulum held by a DC-motor tendon, an elastic-tendon muscle and a ligament: the state saved
// mid-run and restored into a scene built afresh goes on as the scene it came from (the scene
// editor carries running simulations over this way).
TEST(BulletSceneDynamicState, RestoredIntoAFreshSceneItGoesOnAsTheOriginal) {
  const sgal::Scene s = ThreePullers(0.3);
  auto original = MakeScene(s);
  original->SetCommand("motor", 0.5);
  original->SetCommand("muscle", 0.4);
  for (int i = 0; i < 300; ++i) original->Step();
  const sgal::DynamicState saved = original->SaveDynamicState();
  EXPECT_EQ(saved.steps, 300u);
  EXPECT_EQ(saved.commands, (std::vector<double>{0.5, 0.4, 0.0}));

  auto fresh = MakeScene(s);
  fresh->RestoreDynamicState(saved);
  EXPECT_EQ(fresh->time(), original->time());
  EXPECT_EQ(fresh->steps(), 300u);
  EXPECT_EQ(fresh->GetParameter("motor.command"), 0.5);
  const Vector3d at_restore = fresh->BodyStates()[0].pose.position;
  EXPECT_LT((at_restore - original->BodyStates()[0].pose.position).norm(), 1e-12);
  for (size_t t = 0; t < 3; ++t)
    EXPECT_NEAR(fresh->TendonStates()[t].tension, original->TendonStates()[t].tension, 1e-9) << t;
  double largest = 0;
  for (int i = 0; i < 500; ++i) {
    original->Step();
    fresh->Step();
    largest = std::max(
        largest,
        (fresh->BodyStates()[0].pose.position - original->BodyStates()[0].pose.position).norm());
  }
  // the hinge's solver keeps warm-start impulses that a fresh scene starts without: a difference
  // in the last bits, far below what a user could see
  EXPECT_LT(largest, 1e-6) << "the restored scene drifted " << largest << " m in 0.5 s";
  EXPECT_GT((original->BodyStates()[0].pose.position - at_restore).norm(), 1e-3)
      << "the pendulum did not move: the comparison shows nothing";

  sgal::DynamicState wrong = saved;
  wrong.actuators.pop_back();
  EXPECT_THROW(fresh->RestoreDynamicState(wrong), std::invalid_argument);
  wrong = saved;
  wrong.actuators[0].push_back(1.0);
  EXPECT_THROW(fresh->RestoreDynamicState(wrong), std::invalid_argument);
  wrong = saved;
  wrong.engine.push_back(1.0);  // a state of a scene with more to it
  EXPECT_THROW(fresh->RestoreDynamicState(wrong), std::invalid_argument);
  // the first tendon's wrap sides (after the one body and the tendon's length and two speeds):
  // a count that is neither 0 nor its 2 path elements (the path keeps a side per element), or a
  // side that is not -1, 0 or +1
  const size_t count = kEngineValuesPerBody + 3;
  ASSERT_EQ(saved.engine[count], 2.0);
  // refused in the tendons' part, after the bodies' values: the scene is left as it was
  const sgal::DynamicState kept = fresh->SaveDynamicState();
  wrong = saved;
  wrong.engine[count] = 1;
  wrong.engine.erase(wrong.engine.begin() + count + 1);
  wrong.engine[0] += 0.5;  // the first body's pose, which a refused state must not reach
  EXPECT_THROW(fresh->RestoreDynamicState(wrong), std::invalid_argument);
  EXPECT_EQ(fresh->SaveDynamicState().engine, kept.engine) << "a refused state changed the scene";
  // a state that gives no sides (count 0) restores; the path of two points still keeps one per
  // element, so the next saved state is the original's again
  wrong = saved;
  wrong.engine[count] = 0;
  wrong.engine.erase(wrong.engine.begin() + count + 1, wrong.engine.begin() + count + 3);
  auto no_sides = MakeScene(s);
  no_sides->RestoreDynamicState(wrong);
  EXPECT_EQ(no_sides->SaveDynamicState().engine, saved.engine);
  wrong = saved;
  wrong.engine[count + 1] = 2;
  try {
    fresh->RestoreDynamicState(wrong);
    ADD_FAILURE() << "a wrap side of 2 was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("must be -1, 0 or 1"), std::string::npos) << e.what();
  }
}

TEST(BulletSceneDynamicState, APullSwingsThePendulumTowardItsTarget) {
  auto scene = MakeScene(Pendulum(0.4, 0.0));
  sgal::Pull pull;
  pull.body = 0;
  pull.target = Vector3d(0.4, 0, 0);  // level with the pivot
  pull.stiffness = 200;
  pull.damping = 2 * std::sqrt(200.0);
  scene->SetPull(pull);
  for (int i = 0; i < 2000; ++i) scene->Step();
  const Vector3d held = scene->BodyStates()[0].pose.position;
  // held where spring and gravity balance: k (target - p) + m g = 0 along the swing
  EXPECT_GT(held.x(), 0.2) << held.transpose();
  scene->ClearPull();
  for (int i = 0; i < 300; ++i) scene->Step();
  EXPECT_LT(scene->BodyStates()[0].pose.position.z(), held.z() - 0.05) << "it did not fall back";
  pull.body = 5;
  EXPECT_THROW(scene->SetPull(pull), std::out_of_range);
  pull.body = 0;
  pull.stiffness = NAN;
  EXPECT_THROW(scene->SetPull(pull), std::invalid_argument);
}

}  // namespace
}  // namespace caliper::physics_bullet

namespace caliper::physics_bullet {
namespace {

/// Balls dropped onto a ground plane and onto each other (contacts that persist) beside the
/// three-puller pendulum.
sgal::Scene BallsAndPullers() {
  sgal::Scene s = ThreePullers(0.3);
  sgal::Body ground;
  ground.name = "ground";
  ground.type = sgal::BodyType::kStatic;
  ground.pose.position = Vector3d(0, 0, -1.0);
  ground.shapes.push_back({"floor", sgal::Plane{}, {}});
  s.bodies.push_back(ground);
  for (int i = 0; i < 6; ++i)
    s.bodies.push_back(Ball("ball" + std::to_string(i),
                            Vector3d(1.0 + 0.03 * (i % 2), 0.02 * i, -0.9 + 0.11 * i), 0.2, 0.05));
  return s;
}

// What a recording's keyframes do: save the exact state and reset the caches in the live run; a
// scene built afresh, restored from a keyframe in the middle and reset the same way, then steps
// bit for bit as the live run does.
TEST(BulletSceneDynamicState, AKeyframeInTheMiddleRestoresBitForBit) {
  const sgal::Scene s = BallsAndPullers();
  auto live = MakeScene(s);
  live->SetCommand("motor", 0.5);
  live->SetCommand("muscle", 0.4);
  std::vector<sgal::DynamicState> keyframes;
  std::vector<std::vector<sgal::BodyState>> trajectory;
  for (int step = 0; step < 1200; ++step) {
    if (step % 100 == 0) {
      keyframes.push_back(live->SaveDynamicState());
      live->ResetCaches();
    }
    live->Step();
    trajectory.push_back(live->BodyStates());
  }
  // the balls came to rest on each other and on the floor: contacts were there throughout
  const auto last = live->BodyStates();
  EXPECT_LT(last.back().pose.position.z(), -0.5);

  for (const size_t k : {size_t(5), size_t(9)}) {
    auto fresh = MakeScene(s);
    fresh->RestoreDynamicState(keyframes[k]);
    fresh->ResetCaches();
    size_t differing = 0;
    for (int step = static_cast<int>(k) * 100; step < 1200; ++step) {
      if (step % 100 == 0 && step != static_cast<int>(k) * 100) fresh->ResetCaches();
      fresh->Step();
      const auto states = fresh->BodyStates();
      for (size_t b = 0; b < states.size(); ++b)
        if (states[b].pose.position != trajectory[step][b].pose.position ||
            states[b].pose.orientation.coeffs() != trajectory[step][b].pose.orientation.coeffs() ||
            states[b].linear_velocity != trajectory[step][b].linear_velocity)
          ++differing;
    }
    EXPECT_EQ(differing, 0u) << "restored from keyframe " << k << " (step " << k * 100 << ")";
    EXPECT_EQ(fresh->SaveDynamicState().actuators, live->SaveDynamicState().actuators);
  }
  // without the exact numbers (bodies only), the restore is close but not the same bits
  sgal::DynamicState rounded = keyframes[5];
  rounded.engine.clear();
  auto approximate = MakeScene(s);
  approximate->RestoreDynamicState(rounded);
  for (int step = 500; step < 1200; ++step) approximate->Step();
  EXPECT_LT((approximate->BodyStates()[0].pose.position - last[0].pose.position).norm(), 1e-3);
}

}  // namespace
}  // namespace caliper::physics_bullet
