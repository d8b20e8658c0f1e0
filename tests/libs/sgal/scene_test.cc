// The scene description: poses, validation messages, the change filter.
#include <gtest/gtest.h>

#include <cmath>

#include "caliper/sgal/physics_scene.h"
#include "caliper/sgal/scene.h"

namespace caliper::sgal {
namespace {

bool HasError(const std::vector<std::string>& errors, const std::string& part) {
  for (const auto& e : errors)
    if (e.find(part) != std::string::npos) return true;
  return false;
}

Scene TwoBodies() {
  Scene s;
  s.name = "two";
  Body a;
  a.name = "a";
  a.shapes.push_back({"box", Box{}, {}});
  Body b = a;
  b.name = "b";
  b.pose.position = Eigen::Vector3d(1, 0, 0);
  s.bodies = {a, b};
  Constraint c;
  c.name = "hinge";
  c.body_a = "a";
  c.body_b = "b";
  s.constraints.push_back(c);
  Tendon t;
  t.name = "t";
  PathElement p;
  p.body = "a";
  t.path.push_back(p);
  p.body = "b";
  t.path.push_back(p);
  s.tendons.push_back(t);
  Actuator act;
  act.name = "m";
  act.kind = "ligament";
  act.tendon = "t";
  s.actuators.push_back(act);
  return s;
}

TEST(Pose, ComposesAndInverts) {
  Pose a;
  a.position = Eigen::Vector3d(1, 2, 3);
  a.orientation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d p(1, 0, 0);
  EXPECT_TRUE(a.Apply(p).isApprox(Eigen::Vector3d(1, 3, 3)));
  const Pose identity = a * a.Inverse();
  EXPECT_LT(identity.position.norm(), 1e-12);
  EXPECT_NEAR(std::abs(identity.orientation.w()), 1.0, 1e-12);
  EXPECT_TRUE(Pose::FromIsometry(a.ToIsometry()).position.isApprox(a.position));
}

TEST(Validate, AcceptsASoundScene) { EXPECT_TRUE(Validate(TwoBodies()).empty()); }

TEST(Validate, NamesEachProblemAndItsElement) {
  Scene s = TwoBodies();
  s.bodies[0].inertia.mass = 0;
  s.bodies[1].inertia.tensor = Eigen::Vector3d(1, 1, 3).asDiagonal();
  s.constraints[0].body_b = "ghost";
  s.tendons[0].path.pop_back();
  s.actuators[0].tendon = "nowhere";
  s.actuators[0].parameters["stiffness"] = NAN;
  const auto errors = Validate(s);
  EXPECT_TRUE(HasError(errors, "body 'a': mass 0.000000 kg; a dynamic body needs a positive mass"));
  EXPECT_TRUE(HasError(errors, "body 'b': principal moments violate the triangle inequality"));
  EXPECT_TRUE(HasError(errors, "constraint 'hinge': no body 'ghost'"));
  EXPECT_TRUE(HasError(errors, "tendon 't': needs at least two points, has 1"));
  EXPECT_TRUE(HasError(errors, "actuator 'm': no tendon 'nowhere'"));
  EXPECT_TRUE(HasError(errors, "actuator 'm': parameter stiffness is not finite"));
}

TEST(Validate, RejectsNegativeOrNonFiniteJointFriction) {
  Scene s = TwoBodies();
  s.constraints[0].friction[0] = 0.3;
  EXPECT_TRUE(Validate(s).empty());
  s.constraints[0].friction[0] = -0.1;
  s.constraints[0].friction[4] = NAN;
  const auto errors = Validate(s);
  EXPECT_TRUE(HasError(errors, "constraint 'hinge': friction[0] = -0.100000 (N or N m) must be"));
  EXPECT_TRUE(HasError(errors, "constraint 'hinge': friction[4] = nan"));
}

TEST(Validate, CouplingsJoinTwoKnownHingesOrSliders) {
  Scene s = TwoBodies();
  Constraint slider = s.constraints[0];
  slider.name = "slider";
  slider.kind = ConstraintKind::kSlider;
  s.constraints.push_back(slider);
  s.couplings.push_back({"hinge", "slider", 0.01, 0});
  EXPECT_TRUE(Validate(s).empty());
  s.couplings.push_back({"ghost", "hinge", 1, 0});
  s.couplings.push_back({"slider", "slider", 1, NAN});
  s.couplings.push_back({"hinge", "slider", 2, 0});
  Constraint ball = s.constraints[0];
  ball.name = "ball";
  ball.kind = ConstraintKind::kBall;
  s.constraints.push_back(ball);
  s.couplings.push_back({"ball", "hinge", 1, 0});
  const auto errors = Validate(s);
  EXPECT_TRUE(HasError(errors, "coupling of 'hinge' to 'ghost': no constraint (joint) 'ghost'"));
  EXPECT_TRUE(HasError(errors, "coupling of 'slider' to 'slider': a joint cannot follow itself"));
  EXPECT_TRUE(
      HasError(errors, "coupling of 'slider' to 'slider': ratio and offset must be finite"));
  EXPECT_TRUE(HasError(errors, "coupling of 'slider' to 'hinge': joint 'slider' already follows"));
  EXPECT_TRUE(HasError(errors, "coupling of 'hinge' to 'ball': constraint 'ball' is not a hinge"));
}

TEST(Validate, RejectsInertiaThatIsNotPositiveDefinite) {
  Scene s = TwoBodies();
  s.bodies[0].inertia.tensor = Eigen::Vector3d(1, 1, -1).asDiagonal();
  EXPECT_TRUE(HasError(Validate(s), "body 'a': inertia tensor is not positive definite"));
  s.bodies[0].inertia.tensor(0, 1) = 0.5;
  EXPECT_TRUE(HasError(Validate(s), "body 'a': inertia tensor is not symmetric"));
}

TEST(Validate, StaticBodiesNeedNoMass) {
  Scene s = TwoBodies();
  s.bodies[0].type = BodyType::kStatic;
  s.bodies[0].inertia.mass = 0;
  EXPECT_TRUE(Validate(s).empty());
}

TEST(Validate, WrapMustStandBetweenTwoPoints) {
  Scene s = TwoBodies();
  s.obstacles.push_back({"pulley", "a", ObstacleKind::kCylinder, {}, 0.01, 0.02});
  PathElement w;
  w.kind = PathElement::Kind::kWrap;
  w.obstacle = "pulley";
  s.tendons[0].path.push_back(w);
  EXPECT_TRUE(HasError(Validate(s), "tendon 't': wrap 'pulley' must stand between two points"));
  w.obstacle = "missing";
  s.tendons[0].path.insert(s.tendons[0].path.begin() + 1, w);
  EXPECT_TRUE(HasError(Validate(s), "tendon 't': unknown wrap obstacle 'missing'"));
}

TEST(ChangeFilter, ReportsOnlyBodiesThatMovedBeyondTolerance) {
  ChangeFilter filter(1e-3, 1e-3);
  std::vector<BodyState> states(3);
  EXPECT_EQ(filter.Changed(states).size(), 3u) << "the first call reports everything";
  EXPECT_TRUE(filter.Changed(states).empty());
  states[1].pose.position.x() = 5e-4;  // below tolerance
  EXPECT_TRUE(filter.Changed(states).empty());
  states[1].pose.position.x() = 2e-3;
  states[2].pose.orientation = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX());
  EXPECT_EQ(filter.Changed(states), (std::vector<int>{1, 2}));
  EXPECT_TRUE(filter.Changed(states).empty());
  // small steps that add up are reported once they pass the tolerance in total
  states[0].pose.position.y() = 6e-4;
  EXPECT_TRUE(filter.Changed(states).empty());
  states[0].pose.position.y() = 1.2e-3;
  EXPECT_EQ(filter.Changed(states), (std::vector<int>{0}));
}

}  // namespace
}  // namespace caliper::sgal
