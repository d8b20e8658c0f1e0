// Forward kinematics of a scene description against closed-form chains, the positions the
// description itself holds, couplings, and every error it names.
#include "caliper/sgal/kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace caliper::sgal {
namespace {

using Eigen::Vector3d;

constexpr double kL1 = 0.5;  // first link [m]
constexpr double kL2 = 0.3;  // second link up to the slider [m]

Body Link(const std::string& name, const Vector3d& position, BodyType type = BodyType::kDynamic) {
  Body b;
  b.name = name;
  b.type = type;
  b.pose.position = position;
  return b;
}

Constraint Joint(const std::string& name, ConstraintKind kind, const std::string& a,
                 const std::string& b) {
  Constraint c;
  c.name = name;
  c.kind = kind;
  c.body_a = a;
  c.body_b = b;
  return c;
}

/// A static base, two links in the xy plane turning about z (shoulder on the base at the origin,
/// elbow at the end of link1) and a carriage sliding along link2's x axis from kL2: every body
/// frame sits at its joint with x along its link, all drawn at zero.
Scene PlanarArm() {
  Scene s;
  s.name = "planar arm";
  s.bodies = {Link("base", Vector3d::Zero(), BodyType::kStatic), Link("link1", Vector3d::Zero()),
              Link("link2", Vector3d(kL1, 0, 0)), Link("carriage", Vector3d(kL1 + kL2, 0, 0))};
  s.constraints.push_back(Joint("shoulder", ConstraintKind::kHinge, "link1", "base"));
  Constraint elbow = Joint("elbow", ConstraintKind::kHinge, "link2", "link1");
  elbow.frame_b.position = Vector3d(kL1, 0, 0);
  s.constraints.push_back(elbow);
  // the slider's z along link2's x
  Constraint rail = Joint("rail", ConstraintKind::kSlider, "carriage", "link2");
  const Eigen::Quaterniond z_to_x(Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitY()));
  rail.frame_b.position = Vector3d(kL2, 0, 0);
  rail.frame_b.orientation = z_to_x;
  rail.frame_a.orientation = z_to_x;
  s.constraints.push_back(rail);
  return s;
}

double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

TEST(ForwardKinematics, MatchesTheClosedFormOfAPlanarArmWithASlider) {
  const Scene s = PlanarArm();
  for (const auto& [q1, q2, d] :
       {std::tuple{0.3, -1.1, 0.05}, std::tuple{-2.5, 2.9, -0.2}, std::tuple{M_PI, 0.0, 0.0}}) {
    const auto poses = ForwardKinematics(s, {{"shoulder", q1}, {"elbow", q2}, {"rail", d}});
    ASSERT_EQ(poses.size(), 4u);
    const Vector3d elbow(kL1 * std::cos(q1), kL1 * std::sin(q1), 0);
    const Vector3d carriage = elbow + (kL2 + d) * Vector3d(std::cos(q1 + q2), std::sin(q1 + q2), 0);
    EXPECT_LT(poses[0].position.norm(), 1e-15) << "the static base stays";
    EXPECT_LT(poses[1].position.norm(), 1e-15);
    EXPECT_LT((poses[2].position - elbow).norm(), 1e-14);
    EXPECT_LT((poses[3].position - carriage).norm(), 1e-14);
    const Eigen::Quaterniond r1(Eigen::AngleAxisd(q1, Vector3d::UnitZ()));
    const Eigen::Quaterniond r12(Eigen::AngleAxisd(q1 + q2, Vector3d::UnitZ()));
    EXPECT_LT(AngleBetween(poses[1].orientation, r1), 1e-14);
    EXPECT_LT(AngleBetween(poses[2].orientation, r12), 1e-14);
    EXPECT_LT(AngleBetween(poses[3].orientation, r12), 1e-14) << "a slider does not turn";
  }
}

TEST(ForwardKinematics, MeasuresPositionsAsTheEngineDoesAndKeepsThoseNotNamed) {
  // the description drawn at shoulder 0.4, elbow -0.7, rail 0.1: posed by the function itself
  const Scene zero = PlanarArm();
  Scene s = zero;
  const auto drawn = ForwardKinematics(zero, {{"shoulder", 0.4}, {"elbow", -0.7}, {"rail", 0.1}});
  for (size_t i = 0; i < s.bodies.size(); ++i) s.bodies[i].pose = drawn[i];
  const auto measured = JointPositions(s);
  ASSERT_EQ(measured.size(), 3u);
  EXPECT_NEAR(measured.at("shoulder"), 0.4, 1e-14);
  EXPECT_NEAR(measured.at("elbow"), -0.7, 1e-14);
  EXPECT_NEAR(measured.at("rail"), 0.1, 1e-14);
  // nothing named: the description's poses
  const auto same = ForwardKinematics(s, {});
  for (size_t i = 0; i < s.bodies.size(); ++i)
    EXPECT_LT((same[i].position - drawn[i].position).norm(), 1e-14) << s.bodies[i].name;
  // only the shoulder named: the elbow and the rail keep -0.7 and 0.1
  const auto moved = ForwardKinematics(s, {{"shoulder", 1.0}});
  const Vector3d elbow(kL1 * std::cos(1.0), kL1 * std::sin(1.0), 0);
  const Vector3d carriage = elbow + (kL2 + 0.1) * Vector3d(std::cos(0.3), std::sin(0.3), 0);
  EXPECT_LT((moved[3].position - carriage).norm(), 1e-14);
}

TEST(ForwardKinematics, FollowersOfCouplingsFollowTheirLeaderUnlessNamed) {
  Scene s = PlanarArm();
  s.couplings.push_back({"shoulder", "elbow", -0.5, 0.1});
  const double q1 = 0.8, q2 = -0.5 * q1 + 0.1;
  const auto poses = ForwardKinematics(s, {{"shoulder", q1}});
  const Vector3d elbow(kL1 * std::cos(q1), kL1 * std::sin(q1), 0);
  EXPECT_LT(AngleBetween(poses[2].orientation,
                         Eigen::Quaterniond(Eigen::AngleAxisd(q1 + q2, Vector3d::UnitZ()))),
            1e-14);
  EXPECT_LT((poses[2].position - elbow).norm(), 1e-14);
  // a named follower takes the given position
  const auto named = ForwardKinematics(s, {{"shoulder", q1}, {"elbow", 0.0}});
  EXPECT_LT(AngleBetween(named[2].orientation,
                         Eigen::Quaterniond(Eigen::AngleAxisd(q1, Vector3d::UnitZ()))),
            1e-14);
  // a chain of couplings: the rail follows the elbow, which follows the shoulder
  s.couplings.push_back({"elbow", "rail", 0.1, 0.0});
  const auto chained = ForwardKinematics(s, {{"shoulder", q1}});
  const Vector3d carriage =
      elbow + (kL2 + 0.1 * q2) * Vector3d(std::cos(q1 + q2), std::sin(q1 + q2), 0);
  EXPECT_LT((chained[3].position - carriage).norm(), 1e-14);
}

TEST(ForwardKinematics, AFloatingRootKeepsItsPoseAndCarriesItsSubtree) {
  // no joint to the world or the base: link1 floats where it is drawn, turned and moved
  Scene s = PlanarArm();
  s.constraints.erase(s.constraints.begin());
  s.bodies[1].pose.position = Vector3d(1, 2, 3);
  s.bodies[1].pose.orientation = Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitX());
  const auto poses = ForwardKinematics(s, {{"elbow", 0.0}, {"rail", 0.0}});
  EXPECT_LT((poses[1].position - Vector3d(1, 2, 3)).norm(), 1e-15);
  // link1's x is still the world x: the elbow at (1 + L1, 2, 3)
  EXPECT_LT((poses[2].position - Vector3d(1 + kL1, 2, 3)).norm(), 1e-14);
  // fixed constraints place too: a tool fixed 0.1 m along the carriage's y
  s.bodies.push_back(Link("tool", Vector3d::Zero()));
  Constraint weld = Joint("weld", ConstraintKind::kFixed, "tool", "carriage");
  weld.frame_b.position = Vector3d(0, 0.1, 0);
  s.constraints.push_back(weld);
  const auto with_tool = ForwardKinematics(s, {{"elbow", 0.0}, {"rail", 0.0}});
  // the carriage's y is link1's y, which the quarter turn about x made the world z
  EXPECT_LT((with_tool[4].position - (with_tool[3].position + Vector3d(0, 0, 0.1))).norm(), 1e-14);
}

std::string ErrorOf(const Scene& s, const std::map<std::string, double>& q) {
  try {
    ForwardKinematics(s, q);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ForwardKinematics, NamesEveryProblem) {
  const Scene arm = PlanarArm();
  EXPECT_NE(ErrorOf(arm, {{"wrist", 0.1}}).find("no joint 'wrist'"), std::string::npos);
  EXPECT_NE(ErrorOf(arm, {{"rail", NAN}}).find("joint 'rail': position is not finite"),
            std::string::npos);
  Scene ball = arm;
  ball.constraints[1].kind = ConstraintKind::kBall;
  EXPECT_NE(ErrorOf(ball, {{"elbow", 0.1}}).find("joint 'elbow' is a ball"), std::string::npos);
  // a closed chain: the carriage is also hinged to the base
  Scene loop = arm;
  loop.constraints.push_back(Joint("strut", ConstraintKind::kHinge, "carriage", "base"));
  EXPECT_NE(ErrorOf(loop, {}).find("kinematic loop: body 'carriage' is the child (body_a) of both "
                                   "'rail' and 'strut'"),
            std::string::npos)
      << ErrorOf(loop, {});
  // a cycle with no root: link1 hangs from link2 instead of the base
  Scene cycle = arm;
  cycle.constraints[0].body_b = "link2";
  EXPECT_NE(ErrorOf(cycle, {}).find("kinematic loop: the constraints through body"),
            std::string::npos)
      << ErrorOf(cycle, {});
  Scene coupled = arm;
  coupled.couplings.push_back({"shoulder", "elbow", 1, 0});
  coupled.couplings.push_back({"elbow", "shoulder", 1, 0});
  EXPECT_NE(ErrorOf(coupled, {}).find("couplings form a cycle"), std::string::npos)
      << ErrorOf(coupled, {});
  Scene dangling = arm;
  dangling.couplings.push_back({"ghost", "elbow", 1, 0});
  EXPECT_NE(ErrorOf(dangling, {}).find("coupling of 'elbow': no joint 'ghost'"), std::string::npos);
}

}  // namespace
}  // namespace caliper::sgal
