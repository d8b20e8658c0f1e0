#include "caliper/actuators/tendon_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

namespace caliper::testing {
namespace {

using actuators::PathForces;
using actuators::PathGeometry;
using actuators::TendonPath;
using actuators::WorldElement;
using Eigen::Vector3d;
using Kind = sgal::PathElement::Kind;

constexpr double kPi = 3.14159265358979323846;

WorldElement Point(const Vector3d& p, int body = -1, double friction = 0) {
  WorldElement e;
  e.kind = Kind::kPoint;
  e.point = p;
  e.body = body;
  e.friction = friction;
  return e;
}

WorldElement Obstacle(sgal::ObstacleKind kind, const Vector3d& centre, double radius,
                      int body = 7) {
  WorldElement e;
  e.kind = Kind::kWrap;
  e.body = body;
  e.obstacle.kind = kind;
  e.obstacle.pose = Eigen::Isometry3d::Identity();
  e.obstacle.pose.translation() = centre;
  e.obstacle.radius = radius;
  return e;
}

WorldElement Cylinder(const Vector3d& centre, double radius) {
  return Obstacle(sgal::ObstacleKind::kCylinder, centre, radius);
}

WorldElement Sphere(const Vector3d& centre, double radius) {
  return Obstacle(sgal::ObstacleKind::kSphere, centre, radius);
}

PathGeometry Evaluate(const std::vector<WorldElement>& elements) {
  TendonPath path;
  return path.Evaluate(elements);
}

int CountOnWrap(const PathGeometry& g) {
  int n = 0;
  for (const auto& p : g.points) n += p.on_wrap ? 1 : 0;
  return n;
}

// every point on a wrap lies on the surface (distance from the centre, or from the z axis through
// it for a cylinder)
void ExpectOnSurface(const PathGeometry& g, const Vector3d& centre, double radius, bool cylinder) {
  for (const auto& p : g.points) {
    if (!p.on_wrap) continue;
    Vector3d d = p.position - centre;
    if (cylinder) d.z() = 0;
    EXPECT_NEAR(d.norm(), radius, 1e-9);
  }
}

Vector3d Sum(const std::vector<actuators::PointForce>& forces) {
  Vector3d s = Vector3d::Zero();
  for (const auto& f : forces) s += f.force;
  return s;
}

// What an engine that places a path of points itself measures (StraightPieces) is what Evaluate
// gives such a path, bit for bit; the directions it keeps are the pieces'; a wrap's arc is not
// among its straight pieces.
TEST(TendonPathTest, StraightPiecesAreWhatEvaluateMeasuresOfPointsAlone) {
  const std::vector<WorldElement> points = {Point({0, 0, 0}), Point({0.3, 0.1, -0.2}, 2),
                                            Point({0.31, 0.7, 0.05}, 3), Point({1e-3, 2, 0}, 4)};
  const PathGeometry g = Evaluate(points);
  ASSERT_EQ(g.points.size(), 4u);
  std::vector<Vector3d> units;
  EXPECT_EQ(actuators::StraightPieces(g.points, &units), g.length);
  EXPECT_NEAR(g.length,
              Vector3d(0.3, 0.1, -0.2).norm() + Vector3d(0.01, 0.6, 0.25).norm() +
                  Vector3d(0.309, 1.3, -0.05).norm(),
              1e-15);
  ASSERT_EQ(units.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    const Vector3d d = g.points[k + 1].position - g.points[k].position;
    EXPECT_NEAR((units[k] - d.normalized()).norm(), 0, 1e-15) << "piece " << k;
  }
  EXPECT_EQ(actuators::StraightPieces({}, &units), 0.0);
  EXPECT_TRUE(units.empty());
  EXPECT_EQ(actuators::StraightPieces({g.points[0]}, &units), 0.0);
  EXPECT_TRUE(units.empty());
  // two points on top of each other: a piece without a direction (it pulls nowhere)
  EXPECT_EQ(actuators::StraightPieces({g.points[1], g.points[1]}, &units), 0.0);
  ASSERT_EQ(units.size(), 1u);
  EXPECT_EQ(units[0], Vector3d::Zero());

  const PathGeometry wrapped =
      Evaluate({Point({-2, 0.5, 0}), Cylinder({0, 0, 0}, 1), Point({2, 0.5, 0})});
  ASSERT_GT(CountOnWrap(wrapped), 2);
  // the chords between the arc's samples are shorter than the arc Evaluate measures exactly
  EXPECT_LT(actuators::StraightPieces(wrapped.points, &units), wrapped.length);
}

// Forces handed out from the directions StraightPieces kept (what the engine applies) are
// PathForces' to the bit, with capstan friction either way and with a piece of no length.
TEST(TendonPathTest, ForcesFromKeptDirectionsArePathForcesBits) {
  std::vector<WorldElement> elements = {Point({0, 0, 0}, 0), Point({1, 0.2, 0}, 1, 0.3),
                                        Point({1, 0.2, 0}, 2, 0.1), Point({1.1, 1, 0.4}, -1, 0.2),
                                        Point({2, 1.5, -0.3}, 3)};
  PathGeometry g = Evaluate(elements);
  ASSERT_EQ(g.points.size(), 5u);
  std::vector<Vector3d> units;
  actuators::StraightPieces(g.points, &units);
  for (const double speed : {-0.2, 0.0, 0.3}) {
    g.speed = speed;
    const auto expected = PathForces(g, 42.5);
    std::vector<std::pair<size_t, Vector3d>> emitted;
    actuators::EmitPathForces(
        g.points, g.speed, 42.5, [&](size_t k) { return units[k]; },
        [&](size_t k, const Vector3d& f) { emitted.emplace_back(k, f); });
    ASSERT_EQ(emitted.size(), expected.size());
    for (size_t k = 0; k < expected.size(); ++k) {
      EXPECT_EQ(emitted[k].first, k);
      EXPECT_EQ(emitted[k].second, expected[k].force) << "point " << k << ", speed " << speed;
      EXPECT_EQ(expected[k].body, g.points[k].body);
      EXPECT_EQ(expected[k].position, g.points[k].position);
    }
    // friction acted: the tension changed on the way (the via point's body took the difference)
    EXPECT_GT(std::abs(expected.back().force.norm() - 42.5), 1e-3);
    EXPECT_LT(Sum(expected).norm(), 1e-12);
  }
}

TEST(TendonPathTest, StraightPathIsTheSegmentLength) {
  const PathGeometry g = Evaluate({Point({0, 0, 0}), Point({3, 4, 0})});
  EXPECT_DOUBLE_EQ(g.length, 5.0);
  ASSERT_EQ(g.points.size(), 2u);
  EXPECT_FALSE(g.points[0].on_wrap);
  EXPECT_DOUBLE_EQ(g.speed, 0.0);
}

TEST(TendonPathTest, ViaPointsAddTheirSegments) {
  const PathGeometry g = Evaluate(
      {Point({0, 0, 0}, 0), Point({1, 0, 0}, 1, 0.2), Point({1, 2, 0}, 2), Point({1, 2, 2}, -1)});
  EXPECT_DOUBLE_EQ(g.length, 5.0);
  ASSERT_EQ(g.points.size(), 4u);
  EXPECT_EQ(g.points[1].body, 1);
  EXPECT_DOUBLE_EQ(g.points[1].friction, 0.2);
  EXPECT_EQ(g.points[3].body, -1);
}

TEST(TendonPathTest, SphereWrapMatchesHandComputedLength) {
  // two points symmetric about the sphere, the line 0.5 above its centre: two tangent lines of
  // sqrt(d^2 - r^2) and the arc over the top between the tangent points
  const double r = 1, h = 0.5;
  const double d = std::hypot(2.0, h);
  const double arc = kPi - 2 * std::atan2(h, 2.0) - 2 * std::acos(r / d);
  const double expected = 2 * std::sqrt(d * d - r * r) + r * arc;
  const PathGeometry g = Evaluate({Point({-2, h, 0}), Sphere({0, 0, 0}, r), Point({2, h, 0})});
  EXPECT_NEAR(g.length, expected, 1e-12);
  // tangent points, arc samples every 15 degrees at most, on the obstacle's body, over the top
  EXPECT_GE(CountOnWrap(g), 2 + static_cast<int>(std::ceil(arc / (kPi / 12))) - 1);
  ExpectOnSurface(g, Vector3d::Zero(), r, false);
  for (const auto& p : g.points) {
    if (!p.on_wrap) continue;
    EXPECT_EQ(p.body, 7);
    EXPECT_GT(p.position.y(), 0);
    EXPECT_NEAR(p.position.z(), 0, 1e-12);
  }
  // the first tangent point: the segment to it is perpendicular to the radius
  const Vector3d t0 = g.points[1].position;
  EXPECT_NEAR((t0 - g.points[0].position).dot(t0), 0, 1e-12);

  // the same moved and turned in space
  Eigen::Isometry3d move = Eigen::Isometry3d::Identity();
  move.rotate(Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()));
  move.pretranslate(Vector3d(0.3, -1, 2));
  WorldElement sphere = Sphere(move.translation(), r);
  const PathGeometry moved =
      Evaluate({Point(move * Vector3d(-2, h, 0)), sphere, Point(move * Vector3d(2, h, 0))});
  EXPECT_NEAR(moved.length, expected, 1e-12);
  ExpectOnSurface(moved, move.translation(), r, false);
}

TEST(TendonPathTest, SphereWrapThroughTheCentreLine) {
  // the straight line passes through the centre: any plane through it will do, the length is the
  // same: 2 sqrt(3) + r (pi - 2 acos(1/2))
  const PathGeometry g = Evaluate({Point({-2, 0, 0}), Sphere({0, 0, 0}, 1), Point({2, 0, 0})});
  EXPECT_NEAR(g.length, 2 * std::sqrt(3.0) + kPi / 3, 1e-12);
  ExpectOnSurface(g, Vector3d::Zero(), 1, false);
}

TEST(TendonPathTest, CylinderWrapIsAHelix) {
  // unrolled, the path is a straight line: length sqrt(planar^2 + rise^2)
  const double r = 1, h = 0.5, z0 = -1, z1 = 1.5;
  const double d = std::hypot(2.0, h);
  const double arc = kPi - 2 * std::atan2(h, 2.0) - 2 * std::acos(r / d);
  const double planar = 2 * std::sqrt(d * d - r * r) + r * arc;
  const PathGeometry g = Evaluate({Point({-2, h, z0}), Cylinder({0, 0, 0}, r), Point({2, h, z1})});
  EXPECT_NEAR(g.length, std::hypot(planar, z1 - z0), 1e-12);
  ExpectOnSurface(g, Vector3d::Zero(), r, true);
  // the axial coordinate grows in proportion to the unrolled length
  double previous_z = z0;
  for (size_t k = 1; k < g.points.size(); ++k) {
    EXPECT_GT(g.points[k].position.z(), previous_z);
    previous_z = g.points[k].position.z();
  }
  const Vector3d t0 = g.points[1].position;
  const double tangent = std::sqrt(d * d - r * r);
  EXPECT_NEAR(t0.z(), z0 + (z1 - z0) * tangent / planar, 1e-12);

  // the same cylinder turned so that its axis is world x
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.rotate(Eigen::AngleAxisd(kPi / 2, Vector3d::UnitY()));
  WorldElement cyl = Cylinder(Vector3d::Zero(), r);
  cyl.obstacle.pose = turn;
  const PathGeometry turned =
      Evaluate({Point(turn * Vector3d(-2, h, z0)), cyl, Point(turn * Vector3d(2, h, z1))});
  EXPECT_NEAR(turned.length, std::hypot(planar, z1 - z0), 1e-12);
}

TEST(TendonPathTest, NoWrapWhenTheStraightLineMisses) {
  for (const auto& obstacle : {Cylinder({0, 0, 0}, 1), Sphere({0, 0, 0}, 1)}) {
    const PathGeometry g = Evaluate({Point({-2, 1.2, 0}), obstacle, Point({2, 1.2, 0.5})});
    EXPECT_NEAR(g.length, std::hypot(4.0, 0.5), 1e-12);
    EXPECT_EQ(g.points.size(), 2u);
    EXPECT_EQ(CountOnWrap(g), 0);
  }
}

TEST(TendonPathTest, PointInsideTheObstacleGivesTheStraightSegment) {
  const PathGeometry g = Evaluate({Point({-0.5, 0, 0}), Cylinder({0, 0, 0}, 1), Point({2, 0, 0})});
  EXPECT_NEAR(g.length, 2.5, 1e-12);
  EXPECT_EQ(CountOnWrap(g), 0);
}

TEST(TendonPathTest, SidePointChoosesTheSide) {
  const double r = 1, h = 0.3;
  const double d = std::hypot(2.0, h);
  const double tangents = 2 * std::sqrt(d * d - r * r);
  const double over = tangents + r * (kPi - 2 * std::atan2(h, 2.0) - 2 * std::acos(r / d));
  const double under = tangents + r * (kPi + 2 * std::atan2(h, 2.0) - 2 * std::acos(r / d));
  auto run = [&](std::optional<Vector3d> side, double* y_sign) {
    WorldElement cyl = Cylinder({0, 0, 0}, r);
    cyl.side = side;
    const PathGeometry g = Evaluate({Point({-2, h, 0}), cyl, Point({2, h, 0})});
    *y_sign = 0;
    for (const auto& p : g.points)
      if (p.on_wrap) *y_sign += p.position.y() > 0 ? 1 : -1;
    return g.length;
  };
  double sign = 0;
  EXPECT_NEAR(run(std::nullopt, &sign), over, 1e-12);  // shorter way
  EXPECT_GT(sign, 0);
  EXPECT_NEAR(run(Vector3d(0, 3, 0), &sign), over, 1e-12);
  EXPECT_GT(sign, 0);
  EXPECT_NEAR(run(Vector3d(0.2, -3, 0), &sign), under, 1e-12);
  EXPECT_LT(sign, 0);

  // as in MuJoCo, a side point beyond the obstacle makes the path wrap even when the straight line
  // misses it
  const double hm = 1.5, dm = std::hypot(2.0, hm);
  WorldElement cyl = Cylinder({0, 0, 0}, r);
  cyl.side = Vector3d(0, -2, 0);
  const PathGeometry g = Evaluate({Point({-2, hm, 0}), cyl, Point({2, hm, 0})});
  EXPECT_NEAR(
      g.length,
      2 * std::sqrt(dm * dm - r * r) + r * (kPi + 2 * std::atan2(hm, 2.0) - 2 * std::acos(r / dm)),
      1e-12);
  ExpectOnSurface(g, Vector3d::Zero(), r, true);
}

TEST(TendonPathTest, SidePointInsideDrawsThePathOntoTheSurface) {
  // MuJoCo's inside wrap: the path bends at one point of the circle; by symmetry at (0, 1)
  WorldElement cyl = Cylinder({0, 0, 0}, 1);
  cyl.side = Vector3d(0, 0.5, 0);
  const PathGeometry g = Evaluate({Point({-2, 1.5, 0}), cyl, Point({2, 1.5, 0})});
  EXPECT_NEAR(g.length, 2 * std::hypot(2.0, 0.5), 1e-9);
  ASSERT_EQ(g.points.size(), 3u);
  EXPECT_TRUE(g.points[1].on_wrap);
  EXPECT_NEAR((g.points[1].position - Vector3d(0, 1, 0)).norm(), 0, 1e-9);

  // an asymmetric case: the touching point reflects the path (equal angles with the normal)
  const Vector3d a(-3, 1.2, 0), b(1.5, 2, 0);
  const PathGeometry asym = Evaluate({Point(a), cyl, Point(b)});
  ASSERT_EQ(asym.points.size(), 3u);
  const Vector3d t = asym.points[1].position;
  EXPECT_NEAR(t.norm(), 1, 1e-12);
  EXPECT_NEAR((a - t).normalized().dot(t), (b - t).normalized().dot(t), 1e-9);
  EXPECT_LT(asym.length, (a - Vector3d(0, 1, 0)).norm() + (b - Vector3d(0, 1, 0)).norm());
}

TEST(TendonPathTest, KeepsItsSideWhileTheObstacleCrossesTheLine) {
  // an obstacle moves down through the straight line and back up again; the path takes the
  // shorter side when the line first cuts the obstacle and keeps it: the obstacle carries the
  // tendon down with it, and it lifts off only where it touched first
  const double r = 0.5, step = 1e-3;
  std::vector<double> heights;
  for (double y = 0.8; y > -0.8; y -= step) heights.push_back(y);
  for (double y = -0.8; y < 0.8; y += step) heights.push_back(y);

  for (const auto kind : {sgal::ObstacleKind::kCylinder, sgal::ObstacleKind::kSphere}) {
    auto elements = [&](double y) {
      return std::vector<WorldElement>{Point({-2, 0, 0}), Obstacle(kind, {0, y, 0}, r),
                                       Point({2, 0, 0})};
    };
    TendonPath kept;
    double previous = -1;
    double largest_jump = 0;
    bool wrapped = false;
    for (double y : heights) {
      const PathGeometry g = kept.Evaluate(elements(y));
      for (const auto& p : g.points) {
        if (!p.on_wrap) continue;
        wrapped = true;
        EXPECT_LE(p.position.y() - y, 1e-12) << "tendon on the upper side at y = " << y;
        EXPECT_NEAR(p.position.z(), 0, 1e-12) << "out of plane at y = " << y;
      }
      if (previous >= 0) largest_jump = std::max(largest_jump, std::abs(g.length - previous));
      previous = g.length;
    }
    EXPECT_TRUE(wrapped);
    EXPECT_LT(largest_jump, 2.5 * step);
    EXPECT_NEAR(previous, 4.0, 1e-12);  // lifted off again at the end

    // carried: far below the line the kept path still wraps, a fresh one does not
    TendonPath carried;
    for (double y = 0.6; y >= -0.6; y -= step) carried.Evaluate(elements(y));
    EXPECT_GT(carried.Evaluate(elements(-0.6)).length, 4.5);
    EXPECT_NEAR(Evaluate(elements(-0.6)).length, 4.0, 1e-12);
  }
}

// lengthening speed against the central difference of the length along the motion
void ExpectSpeedMatchesDifference(const std::vector<WorldElement>& elements, bool wraps) {
  const double h = 1e-6;
  auto moved = [&](double t) {
    std::vector<WorldElement> m = elements;
    for (auto& e : m) {
      if (e.kind == Kind::kPoint)
        e.point += t * e.velocity;
      else
        e.obstacle.pose.translation() += t * e.velocity;
    }
    return m;
  };
  TendonPath path;
  const PathGeometry g = path.Evaluate(elements);
  EXPECT_EQ(CountOnWrap(g) > 0, wraps);
  const double difference =
      (path.Evaluate(moved(h)).length - path.Evaluate(moved(-h)).length) / (2 * h);
  EXPECT_NEAR(g.speed, difference, 1e-7 * (1 + std::abs(difference)));
}

TEST(TendonPathTest, SpeedMatchesTheFiniteDifferenceOfLength) {
  auto point = [](const Vector3d& p, const Vector3d& v) {
    WorldElement e = Point(p);
    e.velocity = v;
    return e;
  };
  // via points only
  ExpectSpeedMatchesDifference(
      {point({0, 0, 0}, {0.1, 0.2, -0.3}), point({1, 0.5, 0}, {-1, 0, 0.4}),
       point({2, -1, 1}, {0.3, 0.3, 0.3})},
      false);
  // sphere, moving points and a moving obstacle
  WorldElement sphere = Sphere({0.1, 0.05, 0.2}, 0.8);
  sphere.velocity = Vector3d(0.2, -0.4, 0.1);
  ExpectSpeedMatchesDifference(
      {point({-2, 0.3, 0.1}, {0.5, -0.2, 0.3}), sphere, point({2, 0.4, -0.3}, {-0.1, 0.7, 0.2})},
      true);
  // cylinder with an axial rise, a side point
  WorldElement cylinder = Cylinder({0, 0, 0}, 0.6);
  cylinder.obstacle.pose.rotate(Eigen::AngleAxisd(0.4, Vector3d(1, 1, 0).normalized()));
  cylinder.velocity = Vector3d(-0.3, 0.2, 0.5);
  cylinder.side = Vector3d(0, -2, 0);
  ExpectSpeedMatchesDifference(
      {point({-2, 0.2, -1}, {0.2, 0.1, -0.5}), cylinder, point({1.5, 0.3, 1.2}, {0.4, -0.6, 0.1}),
       point({3, 1, 1}, {0, 0, 1})},
      true);
  // inside wrap
  WorldElement inside = Cylinder({0, 0, 0}, 1);
  inside.side = Vector3d(0, 0.5, 0);
  inside.velocity = Vector3d(0.1, 0.3, 0);
  ExpectSpeedMatchesDifference(
      {point({-3, 1.2, 0}, {0.2, 0, 0.1}), inside, point({1.5, 2, 0.5}, {0, -0.4, 0})}, true);
}

TEST(TendonPathTest, ForcesPullPointsTowardTheirNeighboursAndSumToZero) {
  const double tension = 50;  // [N]
  const PathGeometry g = Evaluate({Point({-2, 0.3, 0}, 1), Cylinder({0, 0, 0}, 1),
                                   Point({2, 0.5, 0.5}, 2), Point({2, 3, 1}, -1)});
  ASSERT_GT(CountOnWrap(g), 2);
  const auto forces = PathForces(g, tension);
  ASSERT_EQ(forces.size(), g.points.size());
  EXPECT_LT(Sum(forces).norm(), 1e-10);
  // first point: toward the next point with the full tension
  EXPECT_NEAR(
      (forces[0].force - tension * (g.points[1].position - g.points[0].position).normalized())
          .norm(),
      0, 1e-10);
  // the obstacle's body takes the sum of the tensions along the two tangent lines
  Vector3d on_obstacle = Vector3d::Zero();
  size_t first = 0, last = 0;
  for (size_t k = 0; k < forces.size(); ++k) {
    if (!g.points[k].on_wrap) continue;
    EXPECT_EQ(forces[k].body, 7);
    on_obstacle += forces[k].force;
    if (first == 0) first = k;
    last = k;
  }
  const Vector3d expected =
      tension * ((g.points[first - 1].position - g.points[first].position).normalized() +
                 (g.points[last + 1].position - g.points[last].position).normalized());
  EXPECT_NEAR((on_obstacle - expected).norm(), 0, 1e-9);
  // the last point (on the world) is pulled back along the last segment
  EXPECT_EQ(forces.back().body, -1);
  EXPECT_NEAR(forces.back().force.norm(), tension, 1e-10);
}

TEST(TendonPathTest, CapstanFrictionAtAViaPoint) {
  const double tension = 10, mu = 0.3, alpha = kPi / 2;
  std::vector<WorldElement> elements = {Point({0, 0, 0}, 0), Point({1, 0, 0}, 1, mu),
                                        Point({1, 1, 0}, 2)};
  PathGeometry g = Evaluate(elements);
  // pulled by the actuator at the first point (speed <= 0): tension falls past the via point
  auto forces = PathForces(g, tension);
  EXPECT_NEAR(forces[0].force.norm() / forces[2].force.norm(), std::exp(mu * alpha), 1e-12);
  EXPECT_NEAR(forces[2].force.norm(), tension * std::exp(-mu * alpha), 1e-12);
  EXPECT_LT(Sum(forces).norm(), 1e-12);  // the via point's body takes the friction
  // dragged out at the far end (speed > 0): tension rises past it
  g.speed = 0.1;
  forces = PathForces(g, tension);
  EXPECT_NEAR(forces[2].force.norm() / forces[0].force.norm(), std::exp(mu * alpha), 1e-12);
  // no turn, no friction
  g = Evaluate({Point({0, 0, 0}), Point({1, 0, 0}, 1, mu), Point({2, 0, 0})});
  forces = PathForces(g, tension);
  EXPECT_NEAR(forces[2].force.norm(), tension, 1e-12);
}

TEST(TendonPathTest, RejectsAWrapThatIsNotBetweenTwoPoints) {
  TendonPath path;
  EXPECT_THROW(path.Evaluate({Cylinder({0, 0, 0}, 1), Point({1, 0, 0}), Point({2, 0, 0})}),
               std::invalid_argument);
  EXPECT_THROW(path.Evaluate({Point({1, 0, 0})}), std::invalid_argument);
}

}  // namespace
}  // namespace caliper::testing
