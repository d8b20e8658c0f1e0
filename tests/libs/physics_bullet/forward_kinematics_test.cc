// sgal::ForwardKinematics against the Bullet adapter: the joint positions the engine reports,
// put through forward kinematics, give back the body poses the engine has, within the constraint
// solver's error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/sgal/kinematics.h"
#include "test_scenes.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Vector3d;

sgal::Body Link(const std::string& name, const Vector3d& position, double mass,
                const Vector3d& inertia) {
  sgal::Body b;
  b.name = name;
  b.pose.position = position;
  b.inertia.mass = mass;
  b.inertia.com = Vector3d(0.1, 0, 0);  // off the joint: gravity turns each link
  b.inertia.tensor = inertia.asDiagonal();
  return b;  // no shapes: nothing collides
}

/// A static base; link1 hinged to it about the world y axis, starting level; link2 sliding along
/// link1's x on a spring; link3 hinged to link2 about an axis tilted from y, so that the chain
/// leaves the xz plane. Body frames at their joints, x along each link.
sgal::Scene Chain() {
  sgal::Scene s = testing::SceneOnStaticBase("chain");
  s.bodies.push_back(Link("link1", Vector3d::Zero(), 1.0, Vector3d(1e-3, 8e-3, 8e-3)));
  s.bodies.push_back(Link("link2", Vector3d(0.3, 0, 0), 0.6, Vector3d(5e-4, 3e-3, 3e-3)));
  s.bodies.push_back(Link("link3", Vector3d(0.5, 0, 0), 0.4, Vector3d(3e-4, 2e-3, 2e-3)));
  const Eigen::Quaterniond z_to_y(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()));
  s.constraints.push_back(
      testing::Joint("shoulder", sgal::ConstraintKind::kHinge, "link1", "base", z_to_y));
  const Eigen::Quaterniond z_to_x(Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()));
  sgal::Constraint rail = testing::Joint("rail", sgal::ConstraintKind::kSlider, "link2", "link1",
                                         z_to_x, Vector3d(0.3, 0, 0));
  rail.springs[0] = {300.0, 2.0, 0.0};  // [N/m], [N s/m], [m]
  s.constraints.push_back(rail);
  const Eigen::Quaterniond tilted(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(0.4, Vector3d::UnitY()));
  s.constraints.push_back(testing::Joint("elbow", sgal::ConstraintKind::kHinge, "link3", "link2",
                                         tilted, Vector3d(0.2, 0, 0)));
  return s;
}

TEST(ForwardKinematics, GivesTheEnginesPosesFromTheEnginesJointPositions) {
  const sgal::Scene description = Chain();
  auto scene = MakeScene(description);
  double worst_position = 0, worst_angle = 0;  // [m], [rad]
  double travel = 0;                           // how far link3 went [m]
  const Vector3d start = description.bodies[3].pose.position;
  for (int step = 1; step <= 1500; ++step) {
    scene->Step();
    if (step % 50 != 0) continue;
    std::map<std::string, double> q;
    for (const char* joint : {"shoulder", "rail", "elbow"})
      q[joint] = scene->GetParameter(std::string(joint) + ".position");
    const auto computed = sgal::ForwardKinematics(description, q);
    const auto states = scene->BodyStates();
    for (size_t i = 0; i < states.size(); ++i) {
      worst_position =
          std::max(worst_position, (computed[i].position - states[i].pose.position).norm());
      worst_angle = std::max(worst_angle,
                             computed[i].orientation.angularDistance(states[i].pose.orientation));
    }
    travel = std::max(travel, (states[3].pose.position - start).norm());
  }
  // The engine's poses are not exactly on its joints: the solver (float, 10 iterations) leaves
  // gaps, and forward kinematics differs from the engine by about them. Measured: 1e-5 m while
  // the chain swings slowly, 5.0e-4 m and 1.1e-3 rad at worst when the elbow whips round at
  // 30 rad/s (the joints gaping 0.3 mm then; 100 solver iterations do not close them). A wrong
  // sign, axis or frame gives centimetres and tenths of a radian.
  EXPECT_LT(worst_position, 1e-3) << "m";
  EXPECT_LT(worst_angle, 3e-3) << "rad";
  EXPECT_GT(travel, 0.2) << "the chain did swing";
  std::printf("forward kinematics vs Bullet over 1.5 s: %.3g m, %.3g rad, travel %.3g m\n",
              worst_position, worst_angle, travel);
}

}  // namespace
}  // namespace caliper::physics_bullet
