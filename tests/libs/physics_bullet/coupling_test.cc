// Joint couplings (q_follower = ratio * q_leader + offset) in the Bullet adapter: the follower
// tracks its leader, and its load reaches the leader as the coupled system's dynamics say.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "caliper/physics_bullet/bullet_scene.h"
#include "caliper/sgal/kinematics.h"
#include "test_scenes.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Vector3d;

constexpr double kG = 9.81;
constexpr double kRatio = -0.5;
constexpr double kOffset = 0.1;  // [rad]

struct Arm {
  double mass;    // [kg]
  double length;  // hinge to centre of mass [m]
  double iyy;     // about the centre of mass, about the hinge axis [kg m^2]
  double Inertia() const { return iyy + mass * length * length; }
  double GravityTorque(double q) const { return mass * kG * length * std::cos(q); }  // [N m]
};

constexpr Arm kLeader{1.0, 0.2, 2e-3};
constexpr Arm kFollower{0.5, 0.15, 1e-3};

/// Two arms on a static base, hinged about the world y axis 0.3 m apart, level at zero
/// (gravity turns both towards positive angles); the follower coupled to the leader.
sgal::Scene Pair(bool follower_slides = false) {
  sgal::Scene s = testing::SceneOnStaticBase("pair");
  const Eigen::Quaterniond z_to_y(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()));
  auto add = [&](const std::string& name, const Arm& arm, const Vector3d& pivot) {
    sgal::Body b;
    b.name = name;
    b.pose.position = pivot;
    b.inertia.mass = arm.mass;
    b.inertia.com = Vector3d(arm.length, 0, 0);
    b.inertia.tensor = Vector3d(arm.iyy / 2, arm.iyy, arm.iyy).asDiagonal();
    s.bodies.push_back(b);
    s.constraints.push_back(
        testing::Joint(name + "_joint", sgal::ConstraintKind::kHinge, name, "base", z_to_y, pivot));
  };
  add("leader", kLeader, Vector3d::Zero());
  add("follower", kFollower, Vector3d(0, 0.3, 0));
  if (follower_slides) {
    // the follower slides sideways instead (its joint's z along the world x), where its
    // weight does not act: its inertia is its load
    sgal::Constraint& c = s.constraints.back();
    c.kind = sgal::ConstraintKind::kSlider;
    const Eigen::Quaterniond z_to_x(Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()));
    c.frame_a.orientation = z_to_x;
    c.frame_b.orientation = z_to_x;
  }
  s.couplings.push_back({"leader_joint", "follower_joint", kRatio, kOffset});
  // drawn where the coupling holds: the follower at 0.1 while the leader is at 0
  const auto poses = sgal::ForwardKinematics(s, {{"leader_joint", 0.0}});
  for (size_t i = 0; i < poses.size(); ++i) s.bodies[i].pose = poses[i];
  return s;
}

TEST(Coupling, TheFollowerTracksItsLeaderAndLoadsIt) {
  auto scene = MakeScene(Pair());
  EXPECT_NEAR(scene->GetParameter("follower_joint.position"), kOffset, 1e-6) << "drawn coupled";
  // the coupled system has one coordinate: (I_l + r^2 I_f) q_l'' = tau_l + r tau_f, integrated
  // as the engine does (semi-implicit Euler, 1 ms)
  double q = 0, w = 0;
  const double inertia = kLeader.Inertia() + kRatio * kRatio * kFollower.Inertia();
  double worst = 0, worst_leader = 0, range = 0;
  for (int step = 1; step <= 2000; ++step) {
    scene->Step();
    w += 1e-3 *
         (kLeader.GravityTorque(q) + kRatio * kFollower.GravityTorque(kRatio * q + kOffset)) /
         inertia;
    q += 1e-3 * w;
    const double ql = scene->GetParameter("leader_joint.position");
    const double qf = scene->GetParameter("follower_joint.position");
    worst = std::max(worst, std::abs(qf - (kRatio * ql + kOffset)));
    worst_leader = std::max(worst_leader, std::abs(ql - q));
    range = std::max(range, std::abs(ql));
  }
  std::printf(
      "over 2 s: coupling error %.3g rad, leader off the coupled system by %.3g rad, "
      "leader swung %.3g rad\n",
      worst, worst_leader, range);
  // measured 2.1e-3 rad: the coupling spring's give under the follower's load, and its lag (a
  // follower left free ends up 4.5 rad off)
  EXPECT_LT(worst, 5e-3) << "rad";
  EXPECT_GT(range, 2.5) << "the leader swung through most of a half turn";
  // measured 8.5e-4 rad; without the follower's load on it the leader swings as a lone
  // pendulum and is 0.8 rad off within the 2 s
  EXPECT_LT(worst_leader, 0.05) << "rad";
}

TEST(Coupling, ASliderFollowsAHinge) {
  // q_follower [m] = -0.5 m/rad * q_leader + 0.1 m; the coupled system:
  // (I_l + r^2 m_f) q_l'' = tau_l
  auto scene = MakeScene(Pair(true));
  double q = 0, w = 0;
  const double inertia = kLeader.Inertia() + kRatio * kRatio * kFollower.mass;
  double worst = 0, worst_leader = 0;
  for (int step = 1; step <= 2000; ++step) {
    scene->Step();
    w += 1e-3 * kLeader.GravityTorque(q) / inertia;
    q += 1e-3 * w;
    const double ql = scene->GetParameter("leader_joint.position");
    const double qf = scene->GetParameter("follower_joint.position");
    worst = std::max(worst, std::abs(qf - (kRatio * ql + kOffset)));
    worst_leader = std::max(worst_leader, std::abs(ql - q));
  }
  std::printf("slider following a hinge over 2 s: %.3g m, leader off by %.3g rad\n", worst,
              worst_leader);
  // measured 5.8e-4 m and 1.5e-3 rad (uncoupled: 1.6 m and 3.1 rad)
  EXPECT_LT(worst, 5e-3) << "m";
  EXPECT_LT(worst_leader, 0.05) << "rad";
}

TEST(Coupling, UnknownJointsAreAnErrorNamingTheCoupling) {
  sgal::Scene s = Pair();
  s.couplings.push_back({"elbow", "follower_joint", 1, 0});
  try {
    MakeScene(s);
    FAIL() << "a coupling to an unknown joint was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "coupling of 'follower_joint' to 'elbow': no constraint (joint) 'elbow'"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace caliper::physics_bullet
