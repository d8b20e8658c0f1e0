// Tendons never pass through the skeleton: the contact geometry alone, and in the Bullet world.
#include "caliper/actuators/tendon_contact.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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

// The half-space under a plane (z <= 0.2 here, grown by the margin), entered, left, inside all
// along, outside all along, and run parallel to, in a frame that is not the world's.
TEST(SegmentInside, FindsThePartUnderAPlane) {
  const sgal::Geometry floor = sgal::Plane{};
  const WorldShape plane = At(floor, Vector3d(0.3, -0.1, 0.2));
  auto down = SegmentInside(plane, Vector3d(0, 0, 1.2), Vector3d(0, 0, -0.8), 0);
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->first, 0.5, 1e-12);
  EXPECT_EQ(down->second, 1.0);
  auto up = SegmentInside(plane, Vector3d(1, 0, -0.8), Vector3d(0, 0, 1.2), 0.1);
  ASSERT_TRUE(up);
  EXPECT_EQ(up->first, 0.0);
  EXPECT_NEAR(up->second, 0.55, 1e-12) << "the margin lifts the surface to z = 0.3";
  auto under = SegmentInside(plane, Vector3d(0, 0, 0), Vector3d(5, 5, -1), 0);
  ASSERT_TRUE(under);
  EXPECT_EQ(under->first, 0.0);
  EXPECT_EQ(under->second, 1.0);
  EXPECT_FALSE(SegmentInside(plane, Vector3d(0, 0, 0.3), Vector3d(5, 5, 2), 0));
  EXPECT_FALSE(SegmentInside(plane, Vector3d(0, 0, 0.25), Vector3d(9, 0, 0.25), 0)) << "above";
  ASSERT_TRUE(SegmentInside(plane, Vector3d(0, 0, 0.15), Vector3d(9, 0, 0.15), 0)) << "below";
  EXPECT_FALSE(SegmentInside(plane, Vector3d(0, 0, 0.5), Vector3d(0, 0, 0.2), 0))
      << "ends on the surface";
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

TEST(WrapAroundBodies, BisectsAStringAroundASphereToNearlyItsGeodesicLength) {
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
  options.exact_wraps = false;
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

// The bisection's default depth (what every engine uses for the shapes and crossings exact wraps
// leave to it): a string whose ends lie 0.3 m either side of a 0.2 m sphere, 0.05 m off its
// centre, wraps 63 degrees; its length is the geodesic's to 0.1 % (0.063 % measured; a round
// fewer gives about four times the error).
TEST(WrapAroundBodies, TheBisectionsDefaultDepthWrapsADeepCrossingNearlyAtItsGeodesicLength) {
  const double r = 0.2, d = 0.3;
  const sgal::Geometry sphere = sgal::Sphere{r};
  const WorldShape shape = At(sphere, Vector3d(0, 0, -0.05));
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) { out->push_back(&shape); };
  const double D = std::hypot(d, 0.05);
  const double wrap_angle = 2 * std::atan2(d, 0.05) - 2 * std::acos(r / D);
  ASSERT_NEAR(wrap_angle * 180 / M_PI, 63.5, 0.5);
  const double geodesic = 2 * std::sqrt(D * D - r * r) + r * wrap_angle;
  auto bent_length = [&](int depth) {
    PathGeometry path;
    path.points = {{Vector3d(-d, 0, 0), -1}, {Vector3d(d, 0, 0), -1}};
    path.length = 2 * d;
    ContactOptions options;
    options.margin = 0;
    options.exact_wraps = false;
    if (depth > 0) options.max_depth = depth;
    WrapAroundBodies(&path, query, options);
    return path.length;
  };
  const double error = std::abs(bent_length(0) - geodesic) / geodesic;
  EXPECT_LT(error, 1e-3) << "geodesic " << geodesic << " m";
  const double coarser =
      std::abs(bent_length(ContactOptions().max_depth - 1) - geodesic) / geodesic;
  EXPECT_GT(coarser, 2.5 * error) << "one round fewer is about four times less accurate: "
                                   << coarser << " against " << error;
}

// A string from (-1, 0, 0) to (1, 0, 0) past a ball and a pebble, bent.
PathGeometry OverBallAndPebble(const WorldShape& ball, const WorldShape& pebble,
                               const ContactOptions& options) {
  PathGeometry path;
  path.points = {{Vector3d(-1, 0, 0), -1}, {Vector3d(1, 0, 0), -1}};
  path.length = 2;
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) {
    out->push_back(&ball);
    out->push_back(&pebble);
  };
  EXPECT_GT(WrapAroundBodies(&path, query, options), 0) << "the string cuts the ball";
  return path;
}

bool PressesOn(const PathGeometry& path, int body) {
  for (const auto& p : path.points)
    if (p.contact && p.body == body) return true;
  return false;
}

// Exact wraps: the length of the shortest way, and a polygon none of whose edges cuts the shape
// (every edge touches it), turning by at most 45 degrees at a vertex.
// Its length lies between the curve's and the polygon's: a polygon whose edges touch an arc of
// radius r turning by 45 degrees at most is longer than the arc by under 0.0431 r a vertex.
void ExpectATouchingPolygon(const WorldShape& shape, const PathGeometry& path, double r) {
  double polygon = 0;
  for (size_t i = 0; i + 1 < path.points.size(); ++i) {
    EXPECT_FALSE(SegmentInside(shape, path.points[i].position, path.points[i + 1].position, -1e-9))
        << "piece " << i << " cuts into the shape";
    polygon += (path.points[i + 1].position - path.points[i].position).norm();
  }
  EXPECT_GE(polygon, path.length - 1e-12);
  EXPECT_LE(polygon, path.length + 0.0431 * r * (path.points.size() - 2));
  for (size_t i = 1; i + 1 < path.points.size(); ++i) {
    const Vector3d in = path.points[i].position - path.points[i - 1].position;
    const Vector3d out = path.points[i + 1].position - path.points[i].position;
    const double turn = std::atan2(in.cross(out).norm(), in.dot(out));
    EXPECT_LE(turn, M_PI / 4 + 1e-9) << "at point " << i;
    EXPECT_TRUE(path.points[i].contact);
    EXPECT_EQ(path.points[i].body, shape.body);
  }
}

PathGeometry Wrapped(const WorldShape& shape, const Vector3d& a, const Vector3d& b, bool exact,
                     int depth = 3) {
  PathGeometry path;
  path.points = {{a, -1}, {b, -1}};
  path.length = (b - a).norm();
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) { out->push_back(&shape); };
  ContactOptions options;
  options.margin = 0;
  options.max_depth = depth;
  options.exact_wraps = exact;
  options.detour_reach = 10;
  WrapAroundBodies(&path, query, options);
  return path;
}

TEST(WrapAroundBodies, WrapsABallExactlyAtItsGeodesicLength) {
  // the deep crossing above, now to rounding
  const double r = 0.2, d = 0.3;
  const sgal::Geometry sphere = sgal::Sphere{r};
  WorldShape shape = At(sphere, Vector3d(0, 0, -0.05));
  const double D = std::hypot(d, 0.05);
  const double geodesic =
      2 * std::sqrt(D * D - r * r) + r * (2 * std::atan2(d, 0.05) - 2 * std::acos(r / D));
  const PathGeometry path = Wrapped(shape, Vector3d(-d, 0, 0), Vector3d(d, 0, 0), true);
  EXPECT_NEAR(path.length, geodesic, 1e-12);
  EXPECT_EQ(path.points.size(), 4u) << "63 degrees in two equal turns (a power of two) of at most 45";
  ExpectATouchingPolygon(shape, path, r);
  // any plane through the centre: the same length, turned
  shape.pose.linear() = Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d a = shape.pose * Vector3d(-d, 0, 0.05), b = shape.pose * Vector3d(d, 0, 0.05);
  EXPECT_NEAR(Wrapped(shape, a, b, true).length, geodesic, 1e-12);
}

// A capsule crossed along its axis, as a tendon spans a bone from the bone above to the bone
// below: over one cap, along the side, over the other. In the plane through the axis the way is
// two tangents, two arcs of a quarter circle or less and the side's length.
TEST(WrapAroundBodies, WrapsACapsuleCrossedAlongItsAxisAtItsGeodesicLength) {
  const double r = 0.031, h = 0.02;
  const sgal::Geometry capsule = sgal::Capsule{r, 2 * h};
  const WorldShape shape = At(capsule, Vector3d(0.5, 0.2, 1.0), 3);
  const Vector3d a(0.018, 0, -0.1), b(0.018, 0, 0.1);
  const Vector3d u = a - Vector3d(0, 0, -h);
  const double D = u.norm(), phi = std::acos(u.x() / D), alpha = std::acos(r / D);
  const double geodesic = 2 * (std::sqrt(D * D - r * r) + r * (phi - alpha)) + 2 * h;
  const Vector3d at = shape.pose.translation();
  const PathGeometry path = Wrapped(shape, at + a, at + b, true);
  EXPECT_NEAR(path.length, geodesic, 1e-12);
  ExpectATouchingPolygon(shape, path, r);
  // the bisection gets there from below, about four times closer a round
  const double fine = Wrapped(shape, at + a, at + b, false, 10).length;
  EXPECT_GT(fine, geodesic - 1e-6 * geodesic);
  EXPECT_LT(fine, geodesic + 1e-12);
}

// Off the plane through the axis the string twists along the side (a helix) and meets each cap
// in another plane: no closed form. For ends all around a turned capsule the exact wrap must be
// a way round (no piece cuts in), no longer than the bisection refined until it no longer moves,
// and the same in both directions. The bisection's way is not the shortest once the string
// twists: its detours go straight out from the middle of each cut, and a twisted string is
// pulled sideways too (0.21 % longer at a turn of 2.5 rad about the axis).
TEST(WrapAroundBodies, WrapsATurnedCapsuleNoLongerThanAFineBisection) {
  const double r = 0.03, h = 0.03;
  const sgal::Geometry capsule = sgal::Capsule{r, 2 * h};
  WorldShape shape = At(capsule, Vector3d(-0.2, 0.1, 0.4), 1);
  shape.pose.linear() = Eigen::AngleAxisd(0.9, Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  int cases = 0;
  for (double twist : {0.0, 0.6, 1.5, 2.5})
    for (double offset : {0.0, 0.01}) {
      // ends beyond both caps and within the side's radius of the axis (else the string may
      // meet the side first: the bisection's), the far one turned about the axis by `twist`
      const Vector3d a_local(0.015 + offset, -offset, -0.12);
      const Vector3d b_local(0.02 * std::cos(twist), 0.02 * std::sin(twist), 0.09 + offset);
      const Vector3d a = shape.pose * a_local, b = shape.pose * b_local;
      const PathGeometry exact = Wrapped(shape, a, b, true);
      const PathGeometry fine = Wrapped(shape, a, b, false, 11);
      ASSERT_GT(exact.points.size(), 2u) << "twist " << twist << " offset " << offset;
      // the fine bisection's pieces cut corners by up to 1e-8 m
      EXPECT_LE(exact.length, fine.length * (1 + 1e-7)) << "twist " << twist << " offset " << offset;
      EXPECT_GE(exact.length, fine.length * (1 - 3e-3)) << "twist " << twist << " offset " << offset;
      if (twist == 0 && offset == 0) {  // in the plane through the axis: the same way
        EXPECT_NEAR(exact.length, fine.length, 1e-7 * fine.length);
      }
      ExpectATouchingPolygon(shape, exact, r);
      const PathGeometry back = Wrapped(shape, b, a, true);
      EXPECT_NEAR(back.length, exact.length, 1e-12) << "twist " << twist << " offset " << offset;
      ++cases;
    }
  EXPECT_EQ(cases, 8);
}

// Random crossings of balls and of capsules spanned from beyond one end to beyond the other:
// every exact wrap touches and never cuts in (by 1e-9 m), is no shorter than the straight
// segment and no longer than its own polygon, nor than a depth-9 bisection beyond that
// bisection's own corner cutting (2e-6). With one round of bisection allowed, a refused wrap
// leaves a single bisection point and its polygon's length: what was taken shows.
TEST(WrapAroundBodies, ExactWrapsOfRandomCrossingsNeverCutIn) {
  std::mt19937 random(2026);
  std::uniform_real_distribution<double> u(-1, 1);
  const double margin = 0.001;
  int taken[2] = {0, 0}, crossings[2] = {0, 0};
  for (int k = 0; k < 1200; ++k) {
    const bool is_capsule = k % 2 == 1;
    const double r = 0.02 + 0.015 * (u(random) + 1), h = 0.01 + 0.02 * (u(random) + 1);
    const sgal::Geometry geometry =
        is_capsule ? sgal::Geometry(sgal::Capsule{r, 2 * h}) : sgal::Geometry(sgal::Sphere{r});
    WorldShape shape = At(geometry, Vector3d(u(random), u(random), u(random)) * 0.1);
    shape.pose.linear() =
        Eigen::AngleAxisd(M_PI * u(random), Vector3d(u(random), u(random), u(random)).normalized())
            .toRotationMatrix();
    const double reach = r + margin;
    Vector3d a, b;
    if (is_capsule) {  // beyond opposite ends, within the side's radius of the axis
      a = Vector3d(u(random) * 0.7 * reach, u(random) * 0.7 * reach, -h - reach - 0.1 * (u(random) + 1.2));
      b = Vector3d(u(random) * 0.7 * reach, u(random) * 0.7 * reach, h + reach + 0.1 * (u(random) + 1.2));
    } else {  // ends around the ball, often nearly opposite
      a = Vector3d(u(random), u(random), u(random)).normalized() * (reach + 0.2 * (u(random) + 1.1));
      b = k % 4 == 0 ? Vector3d(-a + Vector3d(u(random), u(random), u(random)) * 0.02)
                     : Vector3d(Vector3d(u(random), u(random), u(random)).normalized() *
                                (reach + 0.2 * (u(random) + 1.1)));
    }
    a = shape.pose * a;
    b = shape.pose * b;
    if (!SegmentInside(shape, a, b, margin)) continue;
    ++crossings[is_capsule];
    const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                                 std::vector<const WorldShape*>* out) { out->push_back(&shape); };
    auto wrap = [&](bool exact, int depth) {
      PathGeometry path;
      path.points = {{a, -1}, {b, -1}};
      path.length = (b - a).norm();
      ContactOptions options;
      options.margin = margin;
      options.exact_wraps = exact;
      options.max_depth = depth;
      options.detour_reach = 10;
      WrapAroundBodies(&path, query, options);
      return path;
    };
    const PathGeometry path = wrap(true, 1);
    double polygon = 0;
    for (size_t i = 0; i + 1 < path.points.size(); ++i)
      polygon += (path.points[i + 1].position - path.points[i].position).norm();
    if (!(path.length < polygon - 1e-13)) continue;  // refused: a bisection point
    ++taken[is_capsule];
    for (size_t i = 0; i + 1 < path.points.size(); ++i)
      ASSERT_FALSE(SegmentInside(shape, path.points[i].position, path.points[i + 1].position,
                                 margin - 1e-9))
          << "case " << k << ", piece " << i << " cuts in";
    ASSERT_GE(path.length, (b - a).norm()) << "case " << k;
    ASSERT_LE(path.length, wrap(false, 9).length * (1 + 2e-6)) << "case " << k;
  }
  EXPECT_GT(crossings[0], 250);
  EXPECT_EQ(taken[0], crossings[0]) << "a ball is always wrapped exactly";
  EXPECT_GT(crossings[1], 500);
  EXPECT_GT(taken[1], 0.95 * crossings[1]) << taken[1] << " of " << crossings[1];
}

// Both ends beyond one end plane: over that cap alone, as over a ball.
TEST(WrapAroundBodies, WrapsACapsuleOverOneCapAsOverItsBall) {
  const double r = 0.05, h = 0.1;
  const sgal::Geometry capsule = sgal::Capsule{r, 2 * h}, ball = sgal::Sphere{r};
  const WorldShape shape = At(capsule, Vector3d::Zero());
  const WorldShape cap = At(ball, Vector3d(0, 0, h));
  const Vector3d a(-0.2, 0.01, 0.13), b(0.2, -0.02, 0.12);
  const PathGeometry over_capsule = Wrapped(shape, a, b, true);
  EXPECT_GT(over_capsule.points.size(), 2u);
  EXPECT_NEAR(over_capsule.length, Wrapped(cap, a, b, true).length, 1e-12);
  // the bisection goes out from the capsule's centre, not the cap's: off the great circle
  const double fine = Wrapped(shape, a, b, false, 11).length;
  EXPECT_LE(over_capsule.length, fine);
  EXPECT_GE(over_capsule.length, fine * (1 - 3e-3));
  ExpectATouchingPolygon(shape, over_capsule, r);
}

// What exact wraps do not cover goes to the bisection, unchanged: a capsule crossed across its
// side, a box; and a wrap another shape cuts.
TEST(WrapAroundBodies, LeavesToTheBisectionWhatItDoesNotWrapExactly) {
  const sgal::Geometry capsule = sgal::Capsule{0.03, 0.1}, box = sgal::Box{Vector3d(0.1, 0.1, 0.1)};
  for (const sgal::Geometry* g : {&capsule, &box}) {
    const WorldShape shape = At(*g, Vector3d(0, 0.01, 0.02));
    const Vector3d a(-0.2, 0, 0), b(0.2, 0, 0.01);
    const PathGeometry exact = Wrapped(shape, a, b, true), bisected = Wrapped(shape, a, b, false);
    ASSERT_GT(bisected.points.size(), 2u);
    ASSERT_EQ(exact.points.size(), bisected.points.size());
    for (size_t i = 0; i < exact.points.size(); ++i)
      EXPECT_EQ(exact.points[i].position, bisected.points[i].position);
    EXPECT_EQ(exact.length, bisected.length);
  }
  // a pebble on the big ball's wrap: the wrap is refused, the bisection goes round both
  const sgal::Geometry big = sgal::Sphere{0.2}, small = sgal::Sphere{0.03};
  const WorldShape ball = At(big, Vector3d(0, -0.05, 0), 1);
  const WorldShape pebble = At(small, Vector3d(0.02, 0.17, 0), 2);
  ContactOptions options;
  options.margin = 0;
  options.max_depth = 5;
  options.detour_reach = 1;
  const PathGeometry path = OverBallAndPebble(ball, pebble, options);
  EXPECT_TRUE(PressesOn(path, 2)) << "no detour point on the pebble";
  const double ball_alone = Wrapped(ball, Vector3d(-1, 0, 0), Vector3d(1, 0, 0), true).length;
  EXPECT_GT(path.length, ball_alone + 0.005) << "over the pebble, not under it";
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
  ContactOptions options;
  options.margin = 0.001;
  options.max_depth = 5;
  const PathGeometry path = OverBallAndPebble(ball, pebble, options);
  EXPECT_TRUE(PressesOn(path, 2)) << "no detour point on the pebble";
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

/// A swinging chain of capsules like the bench tree's spine, a ball flying through it and a
/// floor; tendons that press on the body between their ends, tendons beside the chain that touch
/// nothing, and one that ends near the floor. Poses at time `t` [s] from hinge angles of our own.
struct SwingingChain {
  static constexpr int kLinks = 10;
  const sgal::Geometry capsule = sgal::Capsule{0.03, 0.04};
  const sgal::Geometry sphere = sgal::Sphere{0.04};
  const sgal::Geometry floor = sgal::Plane{};
  std::vector<WorldShape> shapes;  // kLinks capsules, the ball, the floor
  struct Tendon {
    int body_a, body_b;
    Vector3d local_a, local_b;  // attachments in the bodies' frames [m]
  };
  std::vector<Tendon> tendons;
  std::vector<Eigen::Isometry3d> frames;

  SwingingChain() {
    shapes.resize(kLinks + 2);
    for (int i = 0; i < kLinks; ++i) shapes[i] = At(capsule, Vector3d::Zero(), i);
    shapes[kLinks] = At(sphere, Vector3d::Zero(), kLinks);
    shapes[kLinks + 1] = At(floor, Vector3d::Zero(), kLinks + 1);
    for (auto& s : shapes) PrepareShape(&s);
    for (int i = 1; i + 1 < kLinks; ++i) {
      // across the middle body, 0.6 radii off its axis: presses on it
      tendons.push_back({i - 1, i + 1, Vector3d(0.018, 0, 0), Vector3d(0.018, 0, 0)});
      // beside the chain, 1.5 radii off: touches nothing while the chain bends gently
      tendons.push_back({i, i + 1, Vector3d(0, 0.045, 0), Vector3d(0, 0.045, 0)});
    }
    // from the base down to just above the floor (within the margin: cuts it at its end)
    tendons.push_back({0, -1, Vector3d(0.045, 0, 0), Vector3d(0.3, 0, 0.0005)});
    Place(0);
  }

  void Place(double t) {
    frames.assign(kLinks, Eigen::Isometry3d::Identity());
    Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
    f.translation() = Vector3d(0, 0, 0.05);
    for (int i = 0; i < kLinks; ++i) {
      const double angle = 0.25 * std::sin(2 * M_PI * (0.7 + 0.13 * i) * t + i);
      f = f * Eigen::AngleAxisd(angle, i % 2 ? Vector3d::UnitX() : Vector3d::UnitY());
      frames[i] = f;
      frames[i].translation() += f.linear() * Vector3d(0, 0, 0.05);  // the body's centre
      shapes[i].pose = frames[i];
      f.translation() += f.linear() * Vector3d(0, 0, 0.1);
    }
    // the ball crosses the chain and the tendons beside it along x, 0.35 m up, once a second
    shapes[kLinks].pose.translation() = Vector3d(0.6 * std::cos(2 * M_PI * 0.5 * t), 0.05, 0.35);
  }

  PathGeometry Path(const Tendon& tendon) const {
    auto point = [&](int body, const Vector3d& local) {
      PathPoint p;
      p.position = body < 0 ? local : Vector3d(frames[body] * local);
      p.body = body;
      return p;
    };
    PathGeometry path;
    path.points = {point(tendon.body_a, tendon.local_a), point(tendon.body_b, tendon.local_b)};
    path.length = (path.points[1].position - path.points[0].position).norm();
    return path;
  }
};

TEST(WrapAroundBodies, RemembersClearSegmentsWithoutChangingAnyPath) {
  // the same search with and without a memory, side by side over 1000 steps of 1 ms: every
  // point and length bit for bit, and most searches of the tendons that touch nothing skipped
  SwingingChain chain;
  std::vector<ContactMemory> memories(chain.tendons.size());
  ContactScratch with_memory, without;
  int searches = 0, segments = 0, pressing = 0, on_floor = 0, ball_hits = 0;
  auto query_all = [&](int* count) {
    return [&chain, count](const Vector3d&, const Vector3d&, double,
                           std::vector<const WorldShape*>* out) {
      if (count != nullptr) ++*count;
      for (const auto& s : chain.shapes) out->push_back(&s);
    };
  };
  const ShapeQuery counted = query_all(&searches), plain = query_all(nullptr);
  ContactOptions options;
  options.margin = 0.001;
  options.detour_reach = 0.1;
  double travel = 0;
  std::vector<Vector3d> previous;
  for (int step = 0; step < 1000; ++step) {
    chain.Place(step * 0.001);
    // the engine's odometer: the largest move of a finite shape's origin, summed
    double moved = 0;
    for (size_t k = 0; k < chain.shapes.size(); ++k) {
      const Vector3d c = chain.shapes[k].pose.translation();
      if (k < previous.size() && std::isfinite(chain.shapes[k].bounding_radius))
        moved = std::max(moved, (c - previous[k]).norm());
      if (k >= previous.size()) previous.push_back(c);
      previous[k] = c;
    }
    travel += moved;
    for (size_t ti = 0; ti < chain.tendons.size(); ++ti) {
      PathGeometry remembered = chain.Path(chain.tendons[ti]);
      PathGeometry fresh = remembered;
      const int n =
          WrapAroundBodies(&remembered, counted, options, &with_memory, &memories[ti], travel);
      ASSERT_EQ(n, WrapAroundBodies(&fresh, plain, options, &without)) << "step " << step;
      ASSERT_EQ(remembered.points.size(), fresh.points.size()) << "step " << step;
      for (size_t i = 0; i < fresh.points.size(); ++i) {
        ASSERT_EQ(remembered.points[i].position, fresh.points[i].position)
            << "step " << step << " tendon " << ti << " point " << i;
        ASSERT_EQ(remembered.points[i].body, fresh.points[i].body);
        ASSERT_EQ(remembered.points[i].contact, fresh.points[i].contact);
      }
      ASSERT_EQ(remembered.length, fresh.length) << "step " << step << " tendon " << ti;
      ++segments;
      if (ti % 2 == 0 && ti + 1 < chain.tendons.size()) pressing += n > 0;
      if (ti + 1 == chain.tendons.size()) on_floor += n > 0;
      // the ball on a tendon beside the chain: one the memory may have skipped until then
      if (ti % 2 == 1)
        for (const auto& p : fresh.points)
          ball_hits += p.contact && p.body == SwingingChain::kLinks;
    }
  }
  // what the comparison covered: pressing tendons, the floor and the ball crossing tendons
  EXPECT_GT(pressing, 0.9 * 1000 * (SwingingChain::kLinks - 2));
  EXPECT_EQ(on_floor, 1000);
  EXPECT_GT(ball_hits, 0) << "the ball never met a tendon: the memory was never put to the test";
  // the 8 pressing tendons and the one on the floor are searched at every step (9000 searches);
  // of the 8000 segments beside the chain, all but a few in ten are skipped
  EXPECT_EQ(segments, 17000);
  EXPECT_LT(searches, 9000 + 800) << searches << " searches of " << segments;
}

TEST(WrapAroundBodies, SearchesAgainWhenTheMemoryCannotProveTheAnswer) {
  // a clearance proves nothing for another margin, another routed path, or once the shapes may
  // have travelled as far as it
  const sgal::Geometry sphere = sgal::Sphere{0.1};
  WorldShape ball = At(sphere, Vector3d(-0.8, 0, 0.15), 1);
  PrepareShape(&ball);
  int searches = 0;
  const ShapeQuery query = [&](const Vector3d&, const Vector3d&, double,
                               std::vector<const WorldShape*>* out) {
    ++searches;
    out->push_back(&ball);
  };
  ContactMemory memory;
  ContactScratch scratch;
  auto wrap = [&](double margin, double travel, bool via, double tilt = 0) {
    ContactOptions options;
    options.margin = margin;
    PathGeometry path;
    path.points = {{Vector3d(-1, 0, tilt), -1}, {Vector3d(1, 0, -tilt), -1}};
    if (via) path.points.insert(path.points.begin() + 1, {Vector3d(0, -0.5, 0), -1});
    path.length = 2;
    return WrapAroundBodies(&path, query, options, &scratch, &memory, travel);
  };
  EXPECT_EQ(wrap(0.01, 0, false), 0);
  EXPECT_EQ(searches, 1);
  EXPECT_EQ(wrap(0.01, 0.02, false), 0);
  EXPECT_EQ(searches, 1) << "0.04 m clear, the shapes moved 0.02 m at most: no search";
  EXPECT_GT(wrap(0.06, 0.02, false), 0) << "the thicker string touches the ball";
  EXPECT_EQ(searches, 2);
  EXPECT_EQ(wrap(0.01, 0.02, false), 0);
  EXPECT_EQ(searches, 3) << "what the thicker string found says nothing of the thinner";
  EXPECT_EQ(wrap(0.01, 0.02, true), 0);
  EXPECT_EQ(searches, 5) << "another routed path: both segments searched";
  EXPECT_EQ(wrap(0.01, 0.02, false), 0);
  EXPECT_EQ(searches, 6);
  // the ends move opposite ways, their mean not at all: the string turns into the ball
  EXPECT_GT(wrap(0.01, 0.02, false, 0.07), 0);
  EXPECT_EQ(searches, 7);
  EXPECT_EQ(wrap(0.01, 0.02, false), 0);
  EXPECT_EQ(searches, 8);
  ball.pose.translation().z() = 0.1;  // moved 0.05 m: the travel says so
  EXPECT_GT(wrap(0.01, 0.07, false), 0) << "the ball moved onto the string";
  EXPECT_EQ(searches, 9);
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
  EXPECT_NEAR(-v.z() / dt, expected_force / 1.0, 1e-4 * expected_force)
      << "the exact wrap's first and last pieces are the tangents";
  EXPECT_NEAR(v.x(), 0, 1e-9);
}

// A tendon spanning a bone from the bone above to the bone below, in the engine: its length is
// the geodesic over both caps and along the side, and the bone is pushed aside by the tension
// turned at the two tangents, T (u_out - u_in).
TEST(TendonContact, SpansACapsuleBoneAtItsGeodesicLengthAndPushesItAside) {
  testing::RegisterTestKinds();
  const double r = 0.03, h = 0.02, x0 = 0.018, z0 = 0.1, tension = 10.0;
  sgal::Scene s = StringOverBall(true);
  s.bodies[0].name = "bone";
  s.bodies[0].pose.position = Vector3d::Zero();
  s.bodies[0].shapes = {{"s", sgal::Capsule{r, 2 * h}, {}}};
  s.tendons[0].path[0].position = Vector3d(x0, 0, -z0);
  s.tendons[0].path[1].position = Vector3d(x0, 0, z0);
  auto scene = physics_bullet::MakeScene(s);
  // in the plane y = 0: from a, the tangent to the lower cap's circle on the +x side
  const Vector3d a(x0, 0, -z0), centre(0, 0, -h);
  const Vector3d w = a - centre;
  const double D = w.norm(), alpha = std::acos(r / D), psi = std::atan2(w.z(), w.x()) + alpha;
  const Vector3d touch = centre + r * Vector3d(std::cos(psi), 0, std::sin(psi));
  const double arc = -psi;  // from the tangent point up to the side at angle 0
  ASSERT_GT(arc, 0);
  const double geodesic = 2 * (std::sqrt(D * D - r * r) + r * arc) + 2 * h;
  const auto before = scene->TendonStates()[0];
  EXPECT_GT(before.contacts, 0);
  EXPECT_NEAR(before.length, geodesic, 1e-12);
  // one step: the push, from the bone's speed (mass 1 kg)
  const Vector3d in = (touch - a).normalized();
  const double push = -2 * tension * in.x();
  scene->Step();
  const double dt = scene->description().settings.time_step;
  const Vector3d v = scene->BodyStates()[0].linear_velocity;
  EXPECT_NEAR(v.x() / dt, push, 1e-4 * std::abs(push)) << "push " << push << " N";
  EXPECT_NEAR(v.z() / dt, 0, 1e-4 * std::abs(push));
  EXPECT_NEAR(v.y(), 0, 1e-12);
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

TEST(TendonContact, AStringTheBallLeavesRunsStraightAgain) {
  // pressing on the ball, the string has more than its two points; moved away from it by a
  // restore, it is the straight line between them again, before and after a step
  testing::RegisterTestKinds();
  auto scene = physics_bullet::MakeScene(StringOverBall(true));
  scene->Step();
  ASSERT_GT(scene->TendonStates()[0].contacts, 0);
  ASSERT_GT(scene->TendonStates()[0].points.size(), 2u);
  sgal::DynamicState state = scene->SaveDynamicState();
  state.engine.clear();  // go by the body poses
  state.bodies[0].pose.position = Vector3d(0, 0, -5);
  state.bodies[0].linear_velocity.setZero();
  scene->RestoreDynamicState(state);
  for (int step = 0; step < 2; ++step) {
    const auto tendon = scene->TendonStates()[0];
    EXPECT_EQ(tendon.contacts, 0) << "step " << step;
    ASSERT_EQ(tendon.points.size(), 2u) << "step " << step;
    EXPECT_EQ(tendon.points[0], Vector3d(-1, 0, 0)) << "step " << step;
    EXPECT_EQ(tendon.points[1], Vector3d(1, 0, 0)) << "step " << step;
    EXPECT_EQ(tendon.length, 2.0) << "step " << step;
    scene->Step();
  }
}

TEST(TendonContact, NoticesABallRisingIntoAStringItClearedBefore) {
  // the ball rises from 0.4 m below the string: while it stays clear the engine may skip the
  // string's search, and it must find the ball at the first step its top reaches the string
  testing::RegisterTestKinds();
  sgal::Scene description = StringOverBall(true);
  description.bodies[0].pose.position = Vector3d(0, 0, -0.5);
  auto scene = physics_bullet::MakeScene(description);
  sgal::DynamicState state = scene->SaveDynamicState();
  state.engine.clear();  // go by the body poses and velocities
  state.bodies[0].linear_velocity = Vector3d(0, 0, 1);
  scene->RestoreDynamicState(state);
  int clear_steps = 0, pressing_steps = 0;
  for (int step = 0; step < 600; ++step) {
    scene->Step();
    const double top = scene->BodyStates()[0].pose.position.z() + 0.1;  // radius 0.1 m
    const int contacts = scene->TendonStates()[0].contacts;
    if (std::abs(top) < 1e-6) continue;  // too close to call
    if (top < 0) {
      ++clear_steps;
      ASSERT_EQ(contacts, 0) << "step " << step << ": the ball's top is " << -top << " m below";
    } else {
      ++pressing_steps;
      ASSERT_GT(contacts, 0) << "step " << step << ": the ball's top is " << top << " m above";
    }
  }
  EXPECT_GT(clear_steps, 300);
  EXPECT_GT(pressing_steps, 50);
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
