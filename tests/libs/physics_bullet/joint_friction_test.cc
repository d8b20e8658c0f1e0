// Joint dry friction in the Bullet adapter against the analytic answer: a joint whose load stays
// below its friction does not move; above it, it accelerates with (load - friction) / inertia.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Vector3d;

constexpr double kG = 9.81;

// the arm: 1 kg, centre of mass 0.2 m from a horizontal hinge, starting level
constexpr double kArmMass = 1.0;    // [kg]
constexpr double kArmLength = 0.2;  // hinge to centre of mass [m]
constexpr double kArmIyy = 2e-3;    // about the centre of mass, about the hinge axis [kg m^2]

/// A bar hinged to the world about the y axis at the origin, its centre of mass at +x: gravity
/// turns it with a torque m g L cos(angle) about the hinge's z (= world y).
sgal::Scene Arm(double friction, double world_scale = 1.0) {
  sgal::Scene s;
  s.name = "arm";
  s.settings.world_scale = world_scale;
  sgal::Body arm;
  arm.name = "arm";
  arm.pose.position = Vector3d(kArmLength, 0, 0);
  arm.inertia.mass = kArmMass;
  arm.inertia.tensor = Vector3d(1e-3, kArmIyy, kArmIyy).asDiagonal();
  arm.shapes.push_back({"box", sgal::Box{Vector3d(0.4, 0.02, 0.02)}, {}});
  s.bodies.push_back(arm);
  sgal::Constraint hinge;
  hinge.name = "pivot";
  hinge.kind = sgal::ConstraintKind::kHinge;
  hinge.body_a = "arm";
  const Eigen::Quaterniond z_to_y(Eigen::AngleAxisd(-M_PI / 2, Vector3d::UnitX()));
  hinge.frame_a.position = Vector3d(-kArmLength, 0, 0);
  hinge.frame_a.orientation = z_to_y;
  hinge.frame_b.orientation = z_to_y;
  hinge.friction[0] = friction;
  s.constraints.push_back(hinge);
  return s;
}

/// The arm's angle after `duration` from rest at 0 under gravity and dry friction while it moves
/// forward, I q'' = m g L cos(q) - F, integrated as the engine does (semi-implicit Euler, 1 ms).
double ArmAngle(double friction, double duration) {
  const double inertia = kArmIyy + kArmMass * kArmLength * kArmLength;
  const double h = 1e-3;
  const int steps = static_cast<int>(std::lround(duration / h));
  double q = 0, w = 0;
  for (int i = 0; i < steps; ++i) {
    w += h * (kArmMass * kG * kArmLength * std::cos(q) - friction) / inertia;
    q += h * w;
  }
  return q;
}

constexpr double kSlope = 30 * M_PI / 180;  // incline of the slider below horizontal [rad]
constexpr double kBlockMass = 2.0;          // [kg]

/// A block sliding down a 30 degree incline through the world origin: a slider (or a generic
/// 6-DOF constraint with only its z translation free) along the incline.
sgal::Scene Incline(double friction, bool generic = false) {
  sgal::Scene s;
  s.name = "incline";
  sgal::Body block;
  block.name = "block";
  block.inertia.mass = kBlockMass;
  block.inertia.tensor = Eigen::Matrix3d::Identity() * 2e-3;
  block.shapes.push_back({"box", sgal::Box{Vector3d(0.1, 0.1, 0.1)}, {}});
  s.bodies.push_back(block);
  sgal::Constraint slider;
  slider.name = "rail";
  slider.kind = generic ? sgal::ConstraintKind::kGeneric6Dof : sgal::ConstraintKind::kSlider;
  slider.body_a = "block";
  const Vector3d down_slope(std::cos(kSlope), 0, -std::sin(kSlope));
  const Eigen::Quaterniond z_along(
      Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), down_slope));
  slider.frame_a.orientation = z_along;
  slider.frame_b.orientation = z_along;
  if (generic) {
    for (auto& l : slider.limits) l = {0, 0};  // locked
    slider.limits[2] = {};                     // z free
    slider.friction[2] = friction;
  } else {
    slider.friction[0] = friction;
  }
  s.constraints.push_back(slider);
  return s;
}

void RunFor(sgal::PhysicsScene& scene, double duration) {
  const int steps =
      static_cast<int>(std::lround(duration / scene.description().settings.time_step));
  for (int i = 0; i < steps; ++i) scene.Step();
}

TEST(JointFriction, HingeHoldsWhileGravityTorqueIsBelowTheFriction) {
  // gravity torque m g L = 1.962 N m against 2.2 N m of friction
  auto scene = MakeScene(Arm(2.2));
  RunFor(*scene, 1.0);
  EXPECT_LT(std::abs(scene->GetParameter("pivot.position")), 1e-3) << "rad after 1 s";
  EXPECT_LT(std::abs(scene->GetParameter("pivot.velocity")), 1e-3) << "rad/s after 1 s";
}

TEST(JointFriction, HingeAcceleratesWithGravityTorqueLessFriction) {
  const double friction = 1.0;  // [N m], gravity torque 1.962 N m
  for (const double scale : {1.0, 10.0}) {
    auto scene = MakeScene(Arm(friction, scale));
    RunFor(*scene, 0.2);
    const double expected = ArmAngle(friction, 0.2);
    const double without_friction = ArmAngle(0, 0.2);
    EXPECT_NEAR(scene->GetParameter("pivot.position"), expected, 5e-3 * expected)
        << "world scale " << scale << "; without friction it would be " << without_friction;
  }
}

TEST(JointFriction, SliderHoldsWhileGravityIsBelowTheFriction) {
  // m g sin(30 deg) = 9.81 N against 11 N
  auto scene = MakeScene(Incline(11.0));
  RunFor(*scene, 1.0);
  EXPECT_LT(std::abs(scene->GetParameter("rail.position")), 1e-4) << "m after 1 s";
}

TEST(JointFriction, SliderAcceleratesWithGravityLessFriction) {
  const double friction = 4.0;                                                    // [N]
  const double a = (kBlockMass * kG * std::sin(kSlope) - friction) / kBlockMass;  // 2.905 m/s^2
  auto scene = MakeScene(Incline(friction));
  RunFor(*scene, 0.5);
  // semi-implicit Euler over n steps of h travels a h^2 n (n + 1) / 2: a t^2 / 2 + a h t / 2
  const double h = 1e-3, t = 0.5;
  const double travelled = 0.5 * a * t * t + 0.5 * a * h * t;
  EXPECT_NEAR(scene->GetParameter("rail.position"), travelled, 1e-3 * travelled);
  EXPECT_NEAR(scene->GetParameter("rail.velocity"), a * t, 1e-3 * a * t);
}

TEST(JointFriction, GenericConstraintHoldsAndSlidesLikeTheSlider) {
  const Vector3d down_slope(std::cos(kSlope), 0, -std::sin(kSlope));
  auto held = MakeScene(Incline(11.0, true));
  RunFor(*held, 1.0);
  EXPECT_LT(held->BodyStates()[0].pose.position.norm(), 1e-4) << "m after 1 s";
  const double friction = 4.0;
  const double a = (kBlockMass * kG * std::sin(kSlope) - friction) / kBlockMass;
  auto sliding = MakeScene(Incline(friction, true));
  RunFor(*sliding, 0.5);
  const double travelled = sliding->BodyStates()[0].pose.position.dot(down_slope);
  const double h = 1e-3, t = 0.5;
  const double expected = 0.5 * a * t * t + 0.5 * a * h * t;  // as the slider's
  EXPECT_NEAR(travelled, expected, 1e-3 * expected);
}

TEST(JointFriction, IsAWritableParameterThatActsOnTheNextStep) {
  auto scene = MakeScene(Incline(11.0));
  const int index = scene->ParameterIndex("rail.friction");
  ASSERT_GE(index, 0);
  const auto info = scene->Parameters()[index];
  EXPECT_EQ(info.unit, "N");
  EXPECT_TRUE(info.writable);
  EXPECT_TRUE(info.is_static);
  EXPECT_EQ(scene->GetParameter("rail.friction"), 11.0);
  RunFor(*scene, 0.2);
  EXPECT_LT(std::abs(scene->GetParameter("rail.position")), 1e-4);
  scene->SetParameter("rail.friction", 0.0);
  RunFor(*scene, 0.2);
  // free: 0.5 g sin(30 deg) t^2 = 0.0981 m
  EXPECT_NEAR(scene->GetParameter("rail.position"), 0.5 * kG * 0.5 * 0.04, 2e-3);
  EXPECT_EQ(scene->description().constraints[0].friction[0], 0.0) << "kept for a saved scene";
  try {
    scene->SetParameter("rail.friction", -1);
    FAIL() << "a negative friction was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rail.friction: must not be negative"), std::string::npos)
        << e.what();
  }
  auto arm = MakeScene(Arm(0));
  EXPECT_EQ(arm->Parameters()[arm->ParameterIndex("pivot.friction")].unit, "N m");
}

TEST(JointFriction, ANegativeOrNonFiniteFrictionIsRejectedNamingTheConstraint) {
  for (const double bad : {-0.5, std::nan(""), HUGE_VAL}) {
    try {
      MakeScene(Arm(bad));
      FAIL() << "friction " << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("constraint 'pivot': friction[0]"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace caliper::physics_bullet
