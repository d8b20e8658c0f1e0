#pragma once
// Tendon path geometry, engine-free: the polyline a tendon follows through its attachment and via
// points and around declared wrap obstacles (spheres, cylinders), its length, and the forces a
// tension exerts on the bodies along it. SI units.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "caliper/sgal/scene.h"

namespace caliper::actuators {

/// A wrap obstacle placed in the world for the current body poses.
struct WorldObstacle {
  sgal::ObstacleKind kind = sgal::ObstacleKind::kCylinder;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // cylinder axis = pose z
  double radius = 0.01;  // [m]
  double length = 0.05;  // [m], cylinders
};

/// One element of a tendon path in world coordinates.
struct WorldElement {
  sgal::PathElement::Kind kind = sgal::PathElement::Kind::kPoint;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // kPoint: world position [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // kPoint: world velocity; kWrap: velocity of the obstacle's origin [m/s]
  int body = -1;           // body the point or obstacle is fixed to (-1: the world)
  double friction = 0;     // kPoint: capstan coefficient [-]
  WorldObstacle obstacle;  // kWrap
  std::optional<Eigen::Vector3d> side;  // kWrap: side point in world coordinates
};

/// A point of the evaluated path.
struct PathPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world [m]
  int body = -1;          // body that takes the force at this point (-1: the world)
  double friction = 0;    // capstan coefficient at this point [-]
  bool on_wrap = false;   // tangent or arc point on a wrap obstacle
  bool contact = false;   // inserted where the tendon presses on a body it is not routed over
};

struct PathGeometry {
  std::vector<PathPoint> points;  // in order from the first attachment to the last
  double length = 0;              // [m] (arcs measured exactly, not by their samples)
  double speed = 0;               // lengthening speed [m/s] (from the point velocities)
};

/// The force on one body at one path point.
struct PointForce {
  int body = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world [m]
  Eigen::Vector3d force = Eigen::Vector3d::Zero();     // world [N]
};

/// Evaluates one tendon's path. Keeps, per wrap element, which side the tendon took last time, so
/// that a path does not jump between sides from one step to the next.
class TendonPath {
 public:
  /// Path through the elements (points, with wraps between two points).
  PathGeometry Evaluate(const std::vector<WorldElement>& elements);
  /// The same into *path, reusing its storage (no allocation once it has grown: the engine's
  /// every step).
  void Evaluate(const std::vector<WorldElement>& elements, PathGeometry* path);
  /// The side each wrap took at the last evaluation (the state carried from step to step).
  const std::vector<int>& wrap_sides() const { return wrap_side_; }
  void set_wrap_sides(std::vector<int> sides) { wrap_side_ = std::move(sides); }

 private:
  std::vector<int> wrap_side_;  // per wrap element: 0 not wrapping, +1 / -1 side taken
};

/// The direction of the piece a -> b, and its length into *length [m]: zero for a piece shorter
/// than 1e-12 m (it pulls nowhere). What PathForces takes of each piece.
inline Eigen::Vector3d PieceUnit(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 double* length) {
  const Eigen::Vector3d d = b - a;
  *length = d.norm();  // one root: d / |d| is what normalized() computes
  return *length > 1e-12 ? Eigen::Vector3d(d * (1 / *length)) : Eigen::Vector3d::Zero();
}

/// A path of points alone as TendonPath::Evaluate measures it: the length of its straight pieces
/// [m], bit for bit, with each piece's direction (PieceUnit) into *units, for EmitPathForces. An
/// engine that places such a path's points itself measures it with this.
inline double StraightPieces(const std::vector<PathPoint>& points,
                             std::vector<Eigen::Vector3d>* units) {
  const size_t pieces = points.empty() ? 0 : points.size() - 1;
  units->resize(pieces);
  double length = 0;
  for (size_t k = 0; k < pieces; ++k) {
    double piece;
    (*units)[k] = PieceUnit(points[k].position, points[k + 1].position, &piece);
    length += piece;
  }
  return length;
}

/// PathForces' arithmetic with the forces handed out instead of stored: `unit(k)` gives piece k's
/// direction (points k to k + 1, as PieceUnit), `emit(k, force)` takes the whole force on point k
/// [N], in point order. An engine that kept the pieces' directions from placing the points
/// applies the forces straight from here, with PathForces' bits.
template <class Unit, class Emit>
void EmitPathForces(const std::vector<PathPoint>& points, double speed, double tension, Unit&& unit,
                    Emit&& emit) {
  const size_t n = points.size();
  if (n < 2) {
    for (size_t k = 0; k < n; ++k) emit(k, Eigen::Vector3d::Zero());
    return;
  }
  // capstan: when the path shortens or holds (speed <= 0) the actuator at the first point pulls
  // the tendon through, so tension falls by exp(-mu alpha) past each point with friction; when it
  // lengthens (speed > 0) the tendon is dragged out against the actuator and tension rises by
  // exp(mu alpha) toward the far end. One pass: each piece's direction, the one before it kept
  const double sign = speed > 0 ? 1.0 : -1.0;
  double t = tension;
  Eigen::Vector3d before = Eigen::Vector3d::Zero();   // the last piece's direction (zero at first)
  Eigen::Vector3d pending = Eigen::Vector3d::Zero();  // the force on point k from piece k - 1
  for (size_t k = 0; k + 1 < n; ++k) {
    const Eigen::Vector3d u = unit(k);
    const double mu = points[k].friction;
    if (k > 0 && mu > 0 && !before.isZero() && !u.isZero()) {
      const double straight = std::acos(std::clamp(-before.dot(u), -1.0, 1.0));
      t *= std::exp(sign * mu * (3.14159265358979323846 - straight));
    }
    before = u;
    pending += t * u;
    emit(k, pending);
    pending.setZero();
    pending -= t * u;
  }
  emit(n - 1, pending);
}

/// The same, each piece's direction found from the points.
template <class Emit>
void EmitPathForces(const std::vector<PathPoint>& points, double speed, double tension,
                    Emit&& emit) {
  auto unit = [&](size_t k) {
    double length;
    return PieceUnit(points[k].position, points[k + 1].position, &length);
  };
  EmitPathForces(points, speed, tension, unit, emit);
}

/// The forces a tension [N] (at the actuator end, the first point) exerts: each point is pulled
/// toward its neighbours. With capstan friction at a point the tension changes there by
/// exp(-+mu alpha), alpha the angle the path turns, depending on the sliding direction
/// (`speed` > 0: the tendon is pulled out toward the first point). Forces on the world (-1)
/// are included too, so that all forces sum to zero when no friction acts.
std::vector<PointForce> PathForces(const PathGeometry& path, double tension);
/// The same into *forces, reusing its storage.
void PathForces(const PathGeometry& path, double tension, std::vector<PointForce>* forces);

}  // namespace caliper::actuators
