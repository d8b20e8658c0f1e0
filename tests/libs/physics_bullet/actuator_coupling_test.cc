// The actuator-body coupling is second order in the time step (issue #16): a free ball hanging on a
// tendon that a DC motor reels in through a linear series-elastic element, against a reference
// computed apart from the project (actuator_coupling_reference.py: the same rig as one stiff ODE,
// SciPy's Radau at tolerance 1e-10). Halving the step must divide the error by about four; the
// tendon's tension must belong to the same instant as the ball's height.
//
// The ball hangs free (no joint) on purpose: Bullet's own joints are first order (a hinged
// pendulum's angle error halves with the step, tendon or not: measured in the closing note of
// #16), which would hide the coupling's order.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Vector3d;

// the rig: keep in step with actuator_coupling_reference.py
constexpr double kAnchor = 0.4;      // the tendon's fixed end straight above the ball [m]
constexpr double kMass = 1.0;        // [kg]
constexpr double kRadius = 0.02;     // [m]
constexpr double kVoltage = 12.0;    // from t = 0 [V]
constexpr double kDuration = 0.5;    // [s]
constexpr double kSample = 0.005;    // [s]

struct Sample {
  double time, height, tension;
};

/// The ball hanging free below the tendon's anchor, starting at the origin (where Bullet's floats
/// round least: the errors measured are the integration's, down to 1e-8 m).
sgal::Scene Rig(double dt) {
  sgal::Scene s;
  s.name = "lift";
  s.settings.time_step = dt;
  sgal::Body ball;
  ball.name = "ball";
  ball.pose.position = Vector3d::Zero();
  ball.inertia.mass = kMass;
  ball.inertia.tensor = Eigen::Matrix3d::Identity() * (0.4 * kMass * kRadius * kRadius);
  ball.shapes.push_back({"ball", sgal::Sphere{kRadius}, {}});
  s.bodies.push_back(ball);
  sgal::Tendon t;
  t.name = "lift";
  sgal::PathElement anchor;
  anchor.position = Vector3d(0, 0, kAnchor);
  sgal::PathElement on_ball;
  on_ball.body = "ball";
  t.path = {anchor, on_ball};
  t.collide_with_bodies = false;
  s.tendons.push_back(t);
  s.actuators.push_back({"motor",
                         "dc_motor_tendon",
                         "lift",
                         {{"stiffness", 5000}, {"damping", 10}, {"rest_length", 0.1},
                          {"pretension", 9.81}},
                         {}});
  return s;
}

std::vector<Sample> Simulate(double dt) {
  auto scene = MakeScene(Rig(dt));
  scene->SetCommand("motor", kVoltage);
  std::vector<Sample> out;
  const int every = static_cast<int>(std::lround(kSample / dt));
  const int steps = static_cast<int>(std::lround(kDuration / dt));
  for (int k = 0; k <= steps; ++k) {
    if (k % every == 0) {
      out.push_back({scene->time(), scene->BodyStates()[0].pose.position.z(),
                     scene->GetParameter("lift.tendon.tension")});
    }
    if (k < steps) scene->Step();
  }
  return out;
}

std::vector<Sample> Reference() {
  const char* source = std::getenv("CALIPER_SOURCE_DIR");
  const char* bin = std::getenv("CALIPER_BIN_DIR");
  if (source == nullptr || bin == nullptr) {
    ADD_FAILURE() << "CALIPER_SOURCE_DIR and CALIPER_BIN_DIR must be set (ctest sets them)";
    return {};
  }
  const std::string csv = std::string(bin) + "/actuator_coupling_reference.csv";
  // Debian's interpreter and its python3-scipy (launch/deps.txt), not whatever python3 is first
  // on the PATH
  const std::string command = "/usr/bin/python3 " + std::string(source) +
                              "/tests/libs/physics_bullet/actuator_coupling_reference.py " + csv;
  if (std::system(command.c_str()) != 0) {
    ADD_FAILURE() << "the reference failed to run: " << command;
    return {};
  }
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<Sample> out;
  while (std::getline(in, line)) {
    Sample s{};
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf", &s.time, &s.height, &s.tension) == 3)
      out.push_back(s);
  }
  return out;
}

struct Errors {
  double height = 0;   // largest |height - reference| over the samples [m]
  double tension = 0;  // the same for the tension [N]
};

Errors Compare(const std::vector<Sample>& run, const std::vector<Sample>& ref) {
  Errors e;
  EXPECT_EQ(run.size(), ref.size());
  for (size_t k = 0; k < std::min(run.size(), ref.size()); ++k) {
    EXPECT_NEAR(run[k].time, ref[k].time, 1e-9);
    e.height = std::max(e.height, std::abs(run[k].height - ref[k].height));
    e.tension = std::max(e.tension, std::abs(run[k].tension - ref[k].tension));
  }
  return e;
}

TEST(ActuatorCoupling, ConvergesWithSecondOrderAgainstAStiffSolverReference) {
  const std::vector<Sample> ref = Reference();
  ASSERT_GT(ref.size(), 90u);
  const double lift = ref.back().height - ref.front().height;
  ASSERT_GT(lift, 0.01) << "the motor lifts the ball [m]";
  std::vector<Errors> errors;
  const std::vector<double> steps = {1e-3, 0.5e-3, 0.25e-3, 0.125e-3};
  for (const double dt : steps) {
    errors.push_back(Compare(Simulate(dt), ref));
    std::printf("dt %.3f ms: height error %.3e m (%.4f %% of the %.1f mm lift), tension error "
                "%.3e N\n",
                dt * 1e3, errors.back().height, 100 * errors.back().height / lift, lift * 1e3,
                errors.back().tension);
  }
  for (size_t k = 1; k < errors.size(); ++k) {
    const double order_height = std::log2(errors[k - 1].height / errors[k].height);
    const double order_tension = std::log2(errors[k - 1].tension / errors[k].tension);
    std::printf("dt %.3f -> %.3f ms: order %.2f (height), %.2f (tension)\n", steps[k - 1] * 1e3,
                steps[k] * 1e3, order_height, order_tension);
    // second order: the error falls about fourfold with each halving (a first-order coupling
    // halves it). At 0.125 ms the errors (1e-8 m) reach what Bullet's single-precision state
    // rounds to over 4000 steps: that halving is shown, not judged.
    if (steps[k] < 0.2e-3) continue;
    EXPECT_GT(order_height, 1.8) << "at dt " << steps[k] * 1e3 << " ms";
    EXPECT_GT(order_tension, 1.8) << "at dt " << steps[k] * 1e3 << " ms";
  }
  // The coupling before #16 (actuators advanced on the bodies' start-of-step state, their tension
  // acting through the same step) gave 6.7e-5 m at 1 ms and 1.7e-5 m at 0.25 ms here; the issue's
  // bar is the first at most the second. 2e-6 m also catches a damper read at the mean speed
  // (6.8e-6 m at 1 ms, first order).
  EXPECT_LT(errors[0].height, 1.7e-5);
  EXPECT_LT(errors[0].height, 2e-6);
  // the tension channel belongs to the bodies' instant: at t = 0 it is the tension at rest that
  // acts through the first step (it read 0 before, one step behind)
  const std::vector<Sample> run = Simulate(1e-3);
  EXPECT_NEAR(run[0].tension, 9.81, 1e-9);
}

}  // namespace
}  // namespace caliper::physics_bullet
