// Tendons never pass through the skeleton: the contact geometry alone, and in the Bullet world.
#include "caliper/actuators/tendon_contact.h"

#include <gtest/gtest.h>

#include <cmath>

#include "caliper/physics_bullet/bullet_scene.h"
#include "test_kinds.h"

namespace caliper::actuators {
namespace {

using Eigen::Vector3d;

WorldShape At(const sgal::Geometry& g, const Vector3d& p, int body = 0) {
  WorldShape s;
  s.geometry = &g;
  s.pose = Eigen::Isometry3d::Identity();
  s.pose.translation() = p;
  s.body = body;
  return s;
}

TEST(SegmentInside, FindsTheChordThroughEachPrimitive) {
  const Vector3d a(-1, 0, 0), b(1, 0, 0);
  const sgal::Geometry box = sgal::Box{Vector3d(0.4, 1, 1)};
  auto i = SegmentInside(At(box, Vector3d::Zero()), a, b, 0);
  ASSERT_TRUE(i);
  EXPECT_NEAR(i->first, 0.4, 1e-12);
  EXPECT_NEAR(i->second, 0.6, 1e-12);
  const sgal::Geometry sphere = sgal::Sphere{0.5};
  i = SegmentInside(At(sphere, Vector3d::Zero()), a, b, 0.1);
  ASSERT_TRUE(i);
  EXPECT_NEAR(i->first, 0.2, 1e-12);
  const sgal::Geometry cylinder = sgal::Cylinder{0.25, 0.1};
  i = SegmentInside(At(cylinder, Vector3d::Zero()), a, b, 0);
  ASSERT_TRUE(i);
  EXPECT_NEAR(i->second - i->first, 0.25, 1e-12);
  EXPECT_FALSE(SegmentInside(At(cylinder, Vector3d(0, 0, 0.2)), a, b, 0)) << "above its end";
  const sgal::Geometry capsule = sgal::Capsule{0.1, 1.0};
  i = SegmentInside(At(capsule, Vector3d(0, 0, 0.55)), a, b, 0);  // through the cap
  ASSERT_TRUE(i);
  EXPECT_NEAR(i->second - i->first, 2 * std::sqrt(0.01 - 0.0025) / 2, 1e-9);
  EXPECT_FALSE(SegmentInside(At(sphere, Vector3d(0, 0.6, 0)), a, b, 0));
}

TEST(SegmentInside, TakesAPreparedMeshByTheSameBox) {
  // an off-centre tetrahedron: its box is centred at (0.15, 0, 0.05), half extents (0.15, 0.1,
  // 0.05)
  auto mesh = std::make_shared<sgal::Mesh>();
  mesh->vertices = {{0, -0.1f, 0}, {0.3f, 0, 0}, {0, 0.1f, 0}, {0.1f, 0, 0.1f}};
  mesh->triangles = {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {0, 2, 3}};
  const sgal::Geometry hull = sgal::ConvexHull{mesh};
  WorldShape raw = At(hull, Vector3d(0.2, -0.1, 0.3));
  raw.pose.linear() = Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  WorldShape prepared = raw;
  PrepareShape(&prepared);
  ASSERT_TRUE(prepared.mesh_box);
  EXPECT_TRUE(prepared.mesh_box->first.isApprox(Vector3d(0.15, 0, 0.05), 1e-6));
  EXPECT_TRUE(prepared.mesh_box->second.isApprox(Vector3d(0.15, 0.1, 0.05), 1e-6));
  EXPECT_NEAR(prepared.bounding_radius, 0.3, 1e-6);
  int crossings = 0;
  for (int k = 0; k < 20; ++k) {
    const Vector3d a(-1, -0.1 + 0.01 * k, 0.3 + 0.005 * k), b(1, -0.1, 0.35 - 0.004 * k);
    const auto expected = SegmentInside(raw, a, b, 0.002);
    const auto got = SegmentInside(prepared, a, b, 0.002);
    ASSERT_EQ(expected.has_value(), got.has_value()) << "segment " << k;
    if (!got) continue;
    ++crossings;
    EXPECT_EQ(got->first, expected->first) << "segment " << k;
    EXPECT_EQ(got->second, expected->second) << "segment " << k;
  }
  EXPECT_GT(crossings, 5) << "most of the segments should pass through the hull's box";
}

TEST(WrapAroundBodies, BendsAStringAroundASphereAtNearlyItsGeodesicLength) {
  const double r = 0.2, d = 1.0;
  const sgal::Geometry sphere = sgal::Sphere{r};
  const WorldShape shape = At(sphere, Vector3d(0, 0, -0.05));
  PathGeometry path;
  path.points = {{Vector3d(-d, 0, 0), -1}, {Vector3d(d, 0, 0), -1}};
  path.length = 2 * d;
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) { out->push_back(&shape); };
  ContactOptions options;
  options.margin = 0;
  options.max_depth = 5;
  const int inserted = WrapAroundBodies(&path, query, options);
  EXPECT_GT(inserted, 3);
  for (const auto& p : path.points) {
    EXPECT_GE((p.position - shape.pose.translation()).norm(), r - 1e-9) << "inside the sphere";
    if (p.contact) {
      EXPECT_EQ(p.body, 0);
    }
  }
  for (size_t i = 0; i + 1 < path.points.size(); ++i)
    EXPECT_FALSE(SegmentInside(shape, path.points[i].position, path.points[i + 1].position, -1e-3))
        << "segment " << i << " cuts through";
  // geodesic in the plane through both ends and the centre: two tangents and an arc
  const double D = std::hypot(d, 0.05);
  const double tangent = std::sqrt(D * D - r * r);
  const double chord_angle = 2 * std::atan2(d, 0.05);  // angle at the centre between the ends
  const double arc = r * (chord_angle - 2 * std::acos(r / D));
  const double geodesic = 2 * tangent + arc;
  EXPECT_NEAR(path.length, geodesic, 0.002 * geodesic)
      << "straight " << 2 * d << " m, geodesic " << geodesic << " m";
}

TEST(WrapAroundBodies, LeavesSegmentsAloneThatMissOrEndOnTheBody) {
  const sgal::Geometry box = sgal::Box{Vector3d(0.2, 0.2, 0.2)};
  PathGeometry path;
  path.points = {{Vector3d(-1, 0, 0), 3}, {Vector3d(1, 0, 0), -1}};
  path.length = 2;
  const WorldShape own = At(box, Vector3d::Zero(), 3);      // the tendon is fixed to this very body
  const WorldShape beside = At(box, Vector3d(0, 1, 0), 4);  // beside the path
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) {
    out->push_back(&own);
    out->push_back(&beside);
  };
  EXPECT_EQ(WrapAroundBodies(&path, query, {}), 0);
  EXPECT_EQ(path.length, 2);
}

TEST(WrapAroundBodies, LiftsAStringOutOfTheFloorAlongItsNormal) {
  const sgal::Geometry floor = sgal::Plane{};
  PathGeometry path;
  path.points = {{Vector3d(-1, 0, 0.1), -1}, {Vector3d(1, 0, 0.1), -1}};
  const WorldShape ground = At(floor, Vector3d(0, 0, 0.3), 7);  // 0.2 m above both ends
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) { out->push_back(&ground); };
  path.length = 2;
  ContactOptions options;
  options.margin = 0;
  EXPECT_GT(WrapAroundBodies(&path, query, options), 0);
  for (const auto& p : path.points)
    if (p.contact) {
      EXPECT_NEAR(p.position.z(), 0.3, 1e-6) << "on the surface, not pushed sideways";
      EXPECT_EQ(p.body, 7);
    }
  EXPECT_LT(path.length, 3.0) << "a detour of sensible length, not off to infinity";
}

TEST(WrapAroundBodies, BendsAroundAShapeOnlyItsDetourComesNear) {
  // the string cuts the big ball; the detour over it passes through a small ball that lies
  // beyond the small ball's reach of the straight string
  const sgal::Geometry big = sgal::Sphere{0.2}, small = sgal::Sphere{0.03};
  const WorldShape ball = At(big, Vector3d(0, -0.05, 0), 1);
  const WorldShape pebble = At(small, Vector3d(-0.5, 0.075, 0), 2);
  ASSERT_FALSE(SegmentInside(pebble, Vector3d(-1, 0, 0), Vector3d(1, 0, 0), 0.01))
      << "the straight string must miss the pebble for this test to mean anything";
  PathGeometry path;
  path.points = {{Vector3d(-1, 0, 0), -1}, {Vector3d(1, 0, 0), -1}};
  path.length = 2;
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) {
    out->push_back(&ball);
    out->push_back(&pebble);
  };
  ContactOptions options;
  options.margin = 0.001;
  options.max_depth = 5;
  EXPECT_GT(WrapAroundBodies(&path, query, options), 0);
  bool on_pebble = false;
  for (const auto& p : path.points) on_pebble |= p.contact && p.body == 2;
  EXPECT_TRUE(on_pebble) << "no detour point on the pebble";
  for (size_t i = 0; i + 1 < path.points.size(); ++i)
    EXPECT_FALSE(SegmentInside(pebble, path.points[i].position, path.points[i + 1].position, -1e-3))
        << "segment " << i << " cuts through the pebble";
}

TEST(WrapAroundBodies, GivesTheSameWithReusedBuffers) {
  // one scratch for several paths in turn, as an engine uses it, against fresh buffers each time
  const sgal::Geometry sphere = sgal::Sphere{0.2};
  const sgal::Geometry capsule = sgal::Capsule{0.05, 0.3};
  const WorldShape ball = At(sphere, Vector3d(0, 0, -0.05), 1);
  WorldShape rod = At(capsule, Vector3d(0.5, 0.02, 0), 2);
  rod.pose.linear() = Eigen::AngleAxisd(0.3, Vector3d::UnitY()).toRotationMatrix();
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) {
    out->push_back(&ball);
    out->push_back(&rod);
  };
  ContactScratch scratch;
  for (int k = 0; k < 4; ++k) {
    PathGeometry path;
    path.points = {{Vector3d(-1, 0.01 * k, 0), -1},
                   {Vector3d(0.2, 0.1, 0.02 * k), -1},
                   {Vector3d(1, -0.01 * k, 0), -1}};
    path.length = (path.points[1].position - path.points[0].position).norm() +
                  (path.points[2].position - path.points[1].position).norm();
    PathGeometry fresh = path;
    const int with_scratch = WrapAroundBodies(&path, query, {}, &scratch);
    EXPECT_EQ(with_scratch, WrapAroundBodies(&fresh, query, {}));
    EXPECT_GT(with_scratch, 0) << "path " << k << " should press on a body";
    ASSERT_EQ(path.points.size(), fresh.points.size());
    for (size_t i = 0; i < path.points.size(); ++i) {
      EXPECT_EQ(path.points[i].position, fresh.points[i].position);
      EXPECT_EQ(path.points[i].body, fresh.points[i].body);
    }
    EXPECT_EQ(path.length, fresh.length);
  }
}

sgal::Scene StringOverBall(bool dynamic_ball) {
  sgal::Scene s;
  s.gravity = Vector3d::Zero();
  sgal::Body ball;
  ball.name = "ball";
  ball.type = dynamic_ball ? sgal::BodyType::kDynamic : sgal::BodyType::kStatic;
  ball.pose.position = Vector3d(0, 0, -0.05);
  ball.inertia.mass = 1.0;
  ball.inertia.tensor = Eigen::Matrix3d::Identity() * 0.004;
  ball.shapes.push_back({"s", sgal::Sphere{0.1}, {}});
  s.bodies.push_back(ball);
  sgal::Tendon t;
  t.name = "string";
  t.radius = 0.0;
  sgal::PathElement left, right;
  left.position = Vector3d(-1, 0, 0);
  right.position = Vector3d(1, 0, 0);
  t.path = {left, right};
  s.tendons.push_back(t);
  s.actuators.push_back({"pull", "test_constant_tension", "string", {{"tension", 10.0}}, {}});
  return s;
}

TEST(TendonContact, StringPressesOnABallItWouldCutThrough) {
  testing::RegisterTestKinds();
  auto scene = physics_bullet::MakeScene(StringOverBall(true));
  scene->Step();
  const auto tendon = scene->TendonStates()[0];
  EXPECT_GT(tendon.contacts, 0);
  EXPECT_GT(tendon.length, 2.0) << "the detour is part of the length";
  // the string presses the ball down with 2 T sin(elevation of the tangents)
  const double D = std::hypot(1.0, 0.05);
  const double elevation = std::asin(0.1 / D) - std::atan(0.05);
  const double expected_force = 2 * 10.0 * std::sin(elevation);
  const double dt = scene->description().settings.time_step;
  const Vector3d v = scene->BodyStates()[0].linear_velocity;
  EXPECT_NEAR(-v.z() / dt, expected_force / 1.0, 0.03 * expected_force);
  EXPECT_NEAR(v.x(), 0, 1e-9);
}

TEST(TendonContact, FindsABodyARestoreMovedOntoTheString) {
  // the ball starts 5 m away; a restore by body poses puts it under the string: the path is
  // evaluated at once against where the ball is now
  testing::RegisterTestKinds();
  sgal::Scene description = StringOverBall(true);
  description.bodies[0].pose.position = Vector3d(0, 0, -5);
  auto scene = physics_bullet::MakeScene(description);
  ASSERT_EQ(scene->TendonStates()[0].contacts, 0);
  sgal::DynamicState state = scene->SaveDynamicState();
  state.engine.clear();  // go by the body poses
  state.bodies[0].pose.position = Vector3d(0, 0, -0.05);
  scene->RestoreDynamicState(state);
  EXPECT_GT(scene->TendonStates()[0].contacts, 0);
  EXPECT_GT(scene->TendonStates()[0].length, 2.0);
}

TEST(TendonContact, CanBeSwitchedOffToPassStraightThrough) {
  testing::RegisterTestKinds();
  physics_bullet::Options off;
  off.tendon_body_contact = false;
  auto scene = physics_bullet::MakeScene(StringOverBall(false), off);
  scene->Step();
  EXPECT_EQ(scene->TendonStates()[0].contacts, 0);
  EXPECT_DOUBLE_EQ(scene->TendonStates()[0].length, 2.0);
}

}  // namespace
}  // namespace caliper::actuators
