// How the adapter hands a body's shapes and inertia to Bullet: one shape at the centre-of-mass
// frame goes in directly (no compound), every other body in a compound, and both collide alike;
// a tensor already diagonal in the body frame keeps the body's own axes and moves the body as
// the eigen-solver's frame does.
#include <gtest/gtest.h>

#include "caliper/physics_bullet/bullet_scene.h"

namespace caliper::physics_bullet {
namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

const Vector3d kBoxSize(0.1, 0.2, 0.3);  // [m]
constexpr double kBoxMass = 2.0;         // [kg]

/// A 0.1 x 0.2 x 0.3 m box standing level above a floor plane, its edges along the world axes.
/// With `body_turn` [rad] the body frame is turned about z and the shape turned back: the same
/// box, but its tensor in the body frame is no longer diagonal, so Bullet gets a compound.
sgal::Scene BoxOnFloor(double body_turn) {
  sgal::Scene scene;
  sgal::Body floor;
  floor.name = "floor";
  floor.type = sgal::BodyType::kStatic;
  floor.shapes.push_back({"ground", sgal::Plane{}, {}});
  scene.bodies.push_back(floor);
  sgal::Body box;
  box.name = "box";
  const Quaterniond turn(Eigen::AngleAxisd(body_turn, Vector3d::UnitZ()));
  box.pose.position = Vector3d(0, 0, 0.16);
  box.pose.orientation = turn;
  box.inertia.mass = kBoxMass;
  const Vector3d s2 = kBoxSize.cwiseProduct(kBoxSize);
  const Vector3d moments =
      kBoxMass / 12 * Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
  const Matrix3d back = turn.conjugate().toRotationMatrix();
  box.inertia.tensor = back * moments.asDiagonal() * back.transpose();
  sgal::Shape shape{"box", sgal::Box{kBoxSize}, {}};
  shape.pose.orientation = turn.conjugate();
  box.shapes.push_back(shape);
  scene.bodies.push_back(box);
  return scene;
}

double RestingHeight(double body_turn) {
  const sgal::Scene scene = BoxOnFloor(body_turn);
  if (body_turn != 0) {
    const Matrix3d& t = scene.bodies[1].inertia.tensor;
    EXPECT_NE(t(0, 1), 0) << "the turned body's tensor should not be diagonal";
  }
  auto physics = MakeScene(scene);
  for (int i = 0; i < 1000; ++i) physics->Step();
  return physics->BodyStates()[1].pose.position.z();
}

TEST(BodyShapes, ABoxAloneAndABoxInACompoundRestAtTheSameHeight) {
  const double alone = RestingHeight(0);
  const double in_compound = RestingHeight(0.5);
  EXPECT_NEAR(alone, kBoxSize.z() / 2, 1e-3);  // on its 0.1 x 0.2 m face, at half its height
  EXPECT_NEAR(in_compound, alone, 1e-5);
}

/// A free box spinning in space (no gravity), its moments not in ascending order, after 0.2 s.
/// With `tilt` = 0 its tensor is exactly diagonal in the body frame and keeps the body's axes;
/// a tiny off-diagonal `tilt` [kg m^2] sends it through the eigen-solver's sorted frame instead.
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
  const sgal::BodyState sorted_axes = Spun(1e-15);
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
