// How the adapter hands a body's shapes and inertia to Bullet: one shape at the centre of mass
// whose axes hold the tensor's principal axes goes in directly (no compound), in the body's axes
// or turned; every other body goes in a compound, and all collide alike; a tensor already
// diagonal in the body frame keeps the body's own axes and moves the body as the eigen-solver's
// frame does.
#include <gtest/gtest.h>

#include <cmath>

#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

const Vector3d kBoxSize(0.1, 0.2, 0.3);  // [m]
constexpr double kBoxMass = 2.0;         // [kg]

/// A 0.1 x 0.2 x 0.3 m box above a floor plane, its edges along the world axes turned by `tilt`
/// [rad] about x. With `body_turn` [rad] the body frame is turned about z and the shape turned
/// back: the same box, its tensor no longer diagonal in the body frame but still in the shape's
/// axes, so the shape goes to Bullet alone in its own axes. `split` makes the box two stacked
/// halves: the same box and tensor, in a compound.
sgal::Scene BoxOnFloor(double body_turn, bool split, double tilt = 0) {
  sgal::Scene scene;
  sgal::Body floor;
  floor.name = "floor";
  floor.type = sgal::BodyType::kStatic;
  floor.shapes.push_back({"ground", sgal::Plane{}, {}});
  scene.bodies.push_back(floor);
  sgal::Body box;
  box.name = "box";
  const Quaterniond turn = Quaterniond(Eigen::AngleAxisd(tilt, Vector3d::UnitX())) *
                           Quaterniond(Eigen::AngleAxisd(body_turn, Vector3d::UnitZ()));
  const Quaterniond back(Eigen::AngleAxisd(-body_turn, Vector3d::UnitZ()));
  box.pose.position = Vector3d(0, 0, 0.16 + 0.2 * std::sin(std::abs(tilt)));
  box.pose.orientation = turn;
  box.inertia.mass = kBoxMass;
  const Vector3d s2 = kBoxSize.cwiseProduct(kBoxSize);
  const Vector3d moments =
      kBoxMass / 12 * Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
  box.inertia.tensor = back.toRotationMatrix() * moments.asDiagonal() *
                       back.toRotationMatrix().transpose();
  if (split) {
    const Vector3d half(kBoxSize.x(), kBoxSize.y(), kBoxSize.z() / 2);
    for (const double z : {-0.25, 0.25}) {
      sgal::Shape shape{z < 0 ? "lower" : "upper", sgal::Box{half}, {}};
      shape.pose.orientation = back;
      shape.pose.position = back * Vector3d(0, 0, z * kBoxSize.z());
      box.shapes.push_back(shape);
    }
  } else {
    sgal::Shape shape{"box", sgal::Box{kBoxSize}, {}};
    shape.pose.orientation = back;
    box.shapes.push_back(shape);
  }
  scene.bodies.push_back(box);
  return scene;
}

sgal::BodyState After(const sgal::Scene& scene, int steps) {
  auto physics = MakeScene(scene);
  for (int i = 0; i < steps; ++i) physics->Step();
  return physics->BodyStates()[1];
}

TEST(BodyShapes, ABoxAloneAndABoxInACompoundRestAtTheSameHeight) {
  const double alone = After(BoxOnFloor(0, false), 1000).pose.position.z();
  const double in_compound = After(BoxOnFloor(0, true), 1000).pose.position.z();
  EXPECT_NEAR(alone, kBoxSize.z() / 2, 1e-3);  // on its 0.1 x 0.2 m face, at half its height
  EXPECT_NEAR(in_compound, alone, 1e-5);
}

TEST(BodyShapes, ATurnedShapeHoldingThePrincipalAxesMovesAsTheSameShapeUnturned) {
  const sgal::Scene turned = BoxOnFloor(0.5, false);
  const Matrix3d& t = turned.bodies[1].inertia.tensor;
  ASSERT_NE(t(0, 1), 0) << "the turned body's tensor should not be diagonal in its frame";
  const double alone = After(turned, 1000).pose.position.z();
  EXPECT_NEAR(alone, kBoxSize.z() / 2, 1e-3);
  EXPECT_NEAR(After(BoxOnFloor(0.5, true), 1000).pose.position.z(), alone, 1e-5);
  // dropped on an edge, it tips over onto a face exactly as the same box in the body's own axes
  // does (alone too: a compound of two halves differs from both by about 1 mm, its contacts
  // being its own)
  const sgal::Scene dropped = BoxOnFloor(0.5, false, 0.4);
  const sgal::BodyState own = After(dropped, 600);
  const sgal::BodyState level = After(BoxOnFloor(0, false, 0.4), 600);
  EXPECT_GT(own.pose.orientation.angularDistance(dropped.bodies[1].pose.orientation), 0.3)
      << "it should have tipped";
  EXPECT_LT((own.pose.position - level.pose.position).norm(), 1e-9);
  const Quaterniond box_axes = own.pose.orientation * dropped.bodies[1].shapes[0].pose.orientation;
  EXPECT_LT(box_axes.angularDistance(level.pose.orientation), 1e-6);
  EXPECT_LT((own.angular_velocity - level.angular_velocity).norm(), 1e-6);
}

/// A free box spinning in space (no gravity), its moments not in ascending order, after 0.2 s.
/// With `tilt` = 0 its tensor is exactly diagonal in the body frame and keeps the body's axes;
/// a small off-diagonal `tilt` [kg m^2], above the 1e-12 of the trace the adapter drops, sends it
/// through the eigen-solver's sorted frame instead.
sgal::BodyState Spun(double tilt) {
  sgal::Scene scene;
  scene.gravity.setZero();
  sgal::Body body;
  body.name = "spinner";
  body.inertia.mass = 1;
  body.inertia.tensor = Vector3d(3e-3, 1e-3, 2e-3).asDiagonal();  // [kg m^2], not sorted
  body.inertia.tensor(0, 1) = body.inertia.tensor(1, 0) = tilt;
  body.angular_velocity = Vector3d(1, 2, 3);  // [rad/s]
  body.shapes.push_back({"box", sgal::Box{Vector3d(0.1, 0.2, 0.3)}, {}});
  scene.bodies.push_back(body);
  auto physics = MakeScene(scene);
  for (int i = 0; i < 200; ++i) physics->Step();
  return physics->BodyStates()[0];
}

TEST(BodyShapes, ADiagonalTensorMovesTheBodyAsTheSolversFrameDoes) {
  const sgal::BodyState own_axes = Spun(0);
  const sgal::BodyState sorted_axes = Spun(1e-9);  // 1.7e-7 of the trace
  // it turned well away from where it started: moments on the wrong axes would show
  EXPECT_GT(own_axes.pose.orientation.angularDistance(Quaterniond::Identity()), 0.5);
  // the same motion, to Bullet's float precision
  EXPECT_LT(own_axes.pose.orientation.angularDistance(sorted_axes.pose.orientation), 1e-4);
  EXPECT_LT((own_axes.angular_velocity - sorted_axes.angular_velocity).norm(), 1e-4)
      << "angular velocity [rad/s] " << own_axes.angular_velocity.transpose() << " vs "
      << sorted_axes.angular_velocity.transpose();
}

}  // namespace
}  // namespace caliper::physics_bullet
